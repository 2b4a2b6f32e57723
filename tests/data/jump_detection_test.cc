#include "dwellfit/estimator/data/jump_detection.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {
namespace {

using ::testing::ElementsAre;
using ::testing::ElementsAreArray;
using ::testing::EndsWith;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::Not;

constexpr Branch kLo = Branch::kLower;
constexpr Branch kUp = Branch::kUpper;
constexpr Branch kOnly = Branch::kOnly;

const std::string kSource = DWELLFIT_SOURCE_DIR;

Sweep FrequencySweep(const std::string& id, SweepDirection direction,
                     const std::vector<double>& freqs_hz, const std::vector<double>& amplitudes,
                     double a_base = 0.01) {
  Sweep sweep;
  sweep.id = id;
  sweep.direction = direction;
  sweep.kind = SweepKind::kFrequency;
  for (size_t i = 0; i < freqs_hz.size(); ++i) {
    DwellPoint point;
    point.drive_frequency_rad_s = HzToRadPerSecond(freqs_hz[i]);
    point.a_base = a_base;
    point.amplitude = amplitudes.at(i);
    sweep.points.push_back(point);
  }
  return sweep;
}

// A frequency sweep at 1 Hz spacing from 40 Hz: only the amplitudes matter.
Sweep UpSweep(const std::vector<double>& amplitudes) {
  std::vector<double> freqs_hz;
  for (size_t i = 0; i < amplitudes.size(); ++i) freqs_hz.push_back(40.0 + i);
  return FrequencySweep("F", SweepDirection::kUp, freqs_hz, amplitudes);
}

Sweep AmplitudeSweep(const std::string& id, SweepDirection direction, double freq_hz,
                     const std::vector<double>& a_bases, const std::vector<double>& amplitudes) {
  Sweep sweep;
  sweep.id = id;
  sweep.direction = direction;
  sweep.kind = SweepKind::kAmplitude;
  for (size_t i = 0; i < a_bases.size(); ++i) {
    DwellPoint point;
    point.drive_frequency_rad_s = HzToRadPerSecond(freq_hz);
    point.a_base = a_bases[i];
    point.amplitude = amplitudes.at(i);
    sweep.points.push_back(point);
  }
  return sweep;
}

std::vector<Branch> Branches(const Sweep& sweep) {
  std::vector<Branch> branches;
  for (const DwellPoint& point : sweep.points) branches.push_back(point.branch);
  return branches;
}

// Appends a row recorded as missing after the sweep's current last dwell.
void AppendMissing(double freq_hz, double a_base, Sweep* sweep) {
  MissingDwell row;
  row.drive_frequency_rad_s = HzToRadPerSecond(freq_hz);
  row.a_base = a_base;
  row.points_before = static_cast<int>(sweep->points.size());
  sweep->missing.push_back(row);
  ++sweep->dropped_nonpositive;
}

TEST(JumpDetectionTest, UpSweepJumpsDownFromUpperToLowerBranch) {
  Sweep sweep = FrequencySweep("F", SweepDirection::kUp, {41.8, 41.9, 42.0, 42.1, 42.2, 42.3, 42.4},
                               {3.0e-3, 3.6e-3, 4.1e-3, 4.5e-3, 4.7e-3, 2.8e-4, 2.2e-4});
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  const JumpBracket& jump = sweep.jumps[0];
  EXPECT_EQ(jump.kind, JumpKind::kJumpDown);
  EXPECT_EQ(jump.index_before, 4);
  EXPECT_DOUBLE_EQ(jump.control_before, HzToRadPerSecond(42.2));
  EXPECT_DOUBLE_EQ(jump.control_after, HzToRadPerSecond(42.3));
  EXPECT_DOUBLE_EQ(jump.amplitude_before, 4.7e-3);
  EXPECT_DOUBLE_EQ(jump.amplitude_after, 2.8e-4);
  EXPECT_FALSE(jump.into_missing_data);
  EXPECT_FALSE(sweep.jumps_from_config);
  EXPECT_THAT(Branches(sweep), ElementsAre(kUp, kUp, kUp, kUp, kUp, kLo, kLo));
  EXPECT_EQ(DescribeJumps(sweep),
            "F/up: jump_down between 42.20 and 42.30 Hz (a 4.7e-3 -> 2.8e-4)");
}

TEST(JumpDetectionTest, DownSweepJumpsUpFromLowerToUpperBranch) {
  Sweep sweep = FrequencySweep("F", SweepDirection::kDown, {41.0, 40.9, 40.8, 40.7, 40.6, 40.5},
                               {6e-4, 7e-4, 8e-4, 9e-4, 2.9e-3, 2.6e-3});
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  const JumpBracket& jump = sweep.jumps[0];
  EXPECT_EQ(jump.kind, JumpKind::kJumpUp);
  EXPECT_EQ(jump.index_before, 3);
  EXPECT_DOUBLE_EQ(jump.control_before, HzToRadPerSecond(40.7));
  EXPECT_DOUBLE_EQ(jump.control_after, HzToRadPerSecond(40.6));
  EXPECT_DOUBLE_EQ(jump.centre(), HzToRadPerSecond(40.65));
  EXPECT_THAT(Branches(sweep), ElementsAre(kLo, kLo, kLo, kLo, kUp, kUp));
  EXPECT_EQ(DescribeJumps(sweep),
            "F/down: jump_up between 40.70 and 40.60 Hz (a 9.0e-4 -> 2.9e-3)");
}

TEST(JumpDetectionTest, AmplitudeSweepUpJumpsUpInABase) {
  Sweep sweep = AmplitudeSweep("A", SweepDirection::kUp, 41.5,
                               {0.026, 0.028, 0.030, 0.033, 0.0354, 0.036, 0.040},
                               {0.87e-3, 0.94e-3, 1.0e-3, 1.1e-3, 1.2e-3, 4.1e-3, 4.3e-3});
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  const JumpBracket& jump = sweep.jumps[0];
  EXPECT_EQ(jump.kind, JumpKind::kJumpUp);
  EXPECT_EQ(jump.index_before, 4);
  EXPECT_DOUBLE_EQ(jump.control_before, 0.0354);  // a_base, not a frequency
  EXPECT_DOUBLE_EQ(jump.control_after, 0.036);
  EXPECT_THAT(Branches(sweep), ElementsAre(kLo, kLo, kLo, kLo, kLo, kUp, kUp));
  EXPECT_EQ(DescribeJumps(sweep),
            "A/up: jump_up between a_base 0.0354 and 0.036 (a 1.2e-3 -> 4.1e-3)");
}

TEST(JumpDetectionTest, AmplitudeSweepDownJumpsDownInABase) {
  Sweep sweep = AmplitudeSweep("A", SweepDirection::kDown, 41.5,
                               {0.014, 0.012, 0.010, 0.008, 0.0068, 0.006, 0.005},
                               {4.0e-3, 3.8e-3, 3.5e-3, 3.2e-3, 3.0e-3, 6e-4, 5e-4});
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpDown);
  EXPECT_EQ(sweep.jumps[0].index_before, 4);
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_before, 0.0068);
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_after, 0.006);
  EXPECT_THAT(Branches(sweep), ElementsAre(kUp, kUp, kUp, kUp, kUp, kLo, kLo));
}

TEST(JumpDetectionTest, SmoothResonanceHasNoJumpAndEveryPointOnOnlyBranch) {
  // The steps are as large as 1e-4 -> 2e-4, but so are all steps of the
  // curve: the largest |ln ratio| 0.69 is 2.6 robust sigmas (0.27), not 6.
  Sweep sweep = UpSweep({1e-4, 2e-4, 3.5e-4, 6e-4, 1e-3, 6e-4, 3.5e-4, 2e-4});
  const JumpEvidence evidence = WeighJumpEvidence(JumpDetectionOptions(), sweep);
  EXPECT_EQ(evidence.candidate_steps, 7);
  EXPECT_NEAR(evidence.noise_sigma, 0.27, 0.01);
  EXPECT_FALSE(evidence.accepted);
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
  EXPECT_THAT(Branches(sweep), ElementsAreArray(std::vector<Branch>(8, kOnly)));
  EXPECT_EQ(DescribeJumps(sweep), "F/up: no jump (8 dwells, largest a 1.0e-3)");
}

TEST(JumpDetectionTest, LargestStepMustExceedNoiseMultipleTimesRobustSigma) {
  // Steps r = +a, -a, +a, -a, ln 2, +a, -a with a = ln 1.1: median a, median
  // absolute deviation 2a, so sigma = 1.4826 * 2a = 0.2826 and the ln 2 step
  // is 2.45 sigmas.
  const std::vector<double> amplitudes = {1.0e-3, 1.1e-3, 1.0e-3, 1.1e-3,
                                          1.0e-3, 2.0e-3, 2.2e-3, 2.0e-3};
  JumpDetectionOptions options;
  Sweep sweep = UpSweep(amplitudes);
  const JumpEvidence evidence = WeighJumpEvidence(options, sweep);
  EXPECT_EQ(evidence.candidate_steps, 7);
  EXPECT_EQ(evidence.step, 4);
  EXPECT_NEAR(evidence.log_ratio, std::log(2.0), 1e-12);
  EXPECT_EQ(evidence.trend_slope, 0.0);  // frequency sweep: no trend removed
  EXPECT_NEAR(evidence.noise_sigma, 1.4826 * 2.0 * std::log(1.1), 1e-12);

  options.noise_multiple = 2.4;
  DetectJumps(options, &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 4);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpUp);

  options.noise_multiple = 2.5;
  DetectJumps(options, &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
  // The default (6) rejects it too.
  EXPECT_FALSE(WeighJumpEvidence(JumpDetectionOptions(), sweep).accepted);
}

TEST(JumpDetectionTest, RatioMustExceedMinRatio) {
  // Steps up by 1.02 and one down by 2.5 after the sixth dwell: the other
  // steps are all equal (sigma 0), so only min_ratio decides.
  std::vector<double> amplitudes = {1e-3};
  for (int i = 1; i <= 5; ++i) amplitudes.push_back(amplitudes.back() * 1.02);
  amplitudes.push_back(amplitudes.back() / 2.5);
  amplitudes.push_back(amplitudes.back() * 1.02);
  JumpDetectionOptions options;
  options.min_ratio = 2.4;
  Sweep sweep = UpSweep(amplitudes);
  DetectJumps(options, &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 5);

  options.min_ratio = 2.6;
  DetectJumps(options, &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
  // Labels from the earlier detection are reset too.
  EXPECT_THAT(Branches(sweep), ElementsAreArray(std::vector<Branch>(8, kOnly)));
}

TEST(JumpDetectionTest, NoiseFloorHopFarBelowThePeakIsIgnored) {
  // 1e-6 -> 3e-6 is a ratio-3 hop, but 3e-6 < 0.2 * 1e-3.
  const std::vector<double> amplitudes = {1e-6,   3e-6, 3.2e-6, 5e-6,   9e-6, 1.7e-5, 3.2e-5, 6e-5,
                                          1.1e-4, 2e-4, 3.6e-4, 6.5e-4, 1e-3, 7e-4,   4e-4};
  Sweep sweep = UpSweep(amplitudes);
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
  EXPECT_EQ(sweep.points[0].branch, kOnly);

  // Without the amplitude floor the same hop is taken for a jump.
  JumpDetectionOptions no_floor;
  no_floor.min_relative_amplitude = 0.0;
  DetectJumps(no_floor, &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 0);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpUp);
}

TEST(JumpDetectionTest, LargerNoiseFloorHopDoesNotHideTheRealJump) {
  // The 1e-7 -> 1e-6 hop (ratio 10) is the largest step, but lies in the
  // noise floor; the jump is 1e-3 -> 3e-4 (ratio 3.3).
  const std::vector<double> amplitudes = {1e-7,   1e-6,   1.8e-6, 3.2e-6, 5.8e-6, 1e-5,
                                          1.8e-5, 3.2e-5, 5.8e-5, 1e-4,   1.8e-4, 3.2e-4,
                                          5.8e-4, 1e-3,   3e-4,   2.5e-4};
  Sweep sweep = UpSweep(amplitudes);
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpDown);
  EXPECT_EQ(sweep.jumps[0].index_before, 13);
  EXPECT_EQ(sweep.points[0].branch, kUp);
  EXPECT_EQ(sweep.points[13].branch, kUp);
  EXPECT_EQ(sweep.points[14].branch, kLo);
}

TEST(JumpDetectionTest, LargerSideMustReachMinRelativeAmplitude) {
  // The only outstanding step is 3e-4 -> 1e-4, whose larger side is 0.3 of
  // the peak.
  const std::vector<double> amplitudes = {1e-3, 8e-4, 6e-4, 4.5e-4, 3e-4, 1e-4, 8e-5};
  JumpDetectionOptions options;
  options.min_relative_amplitude = 0.3;
  Sweep sweep = UpSweep(amplitudes);
  DetectJumps(options, &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 4);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpDown);

  options.min_relative_amplitude = 0.35;
  DetectJumps(options, &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
}

TEST(JumpDetectionTest, AmplitudeSweepPowerLawGrowthIsNoJump) {
  // a = 1e-3 (a_base / 0.002)^(1/3), a_base 0.002 .. 0.05 in steps of 0.001:
  // the first step alone is a factor 1.145, all later ones smaller, and no
  // step stands out once the trend a ~ a_base^(1/3) is removed.
  std::vector<double> a_bases, amplitudes;
  for (int i = 0; i <= 48; ++i) {
    a_bases.push_back(0.002 + 0.001 * i);
    amplitudes.push_back(1e-3 * std::cbrt(a_bases.back() / 0.002));
  }
  Sweep sweep = AmplitudeSweep("A", SweepDirection::kUp, 40.0, a_bases, amplitudes);
  JumpEvidence evidence = WeighJumpEvidence(JumpDetectionOptions(), sweep);
  EXPECT_NEAR(evidence.trend_slope, 1.0 / 3.0, 1e-9);
  EXPECT_LT(std::abs(evidence.log_excess), 1e-9);
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());

  // The same growth with a jump up by 2.5 between a_base 0.030 and 0.031.
  for (int i = 29; i <= 48; ++i) sweep.points[i].amplitude *= 2.5;
  evidence = WeighJumpEvidence(JumpDetectionOptions(), sweep);
  EXPECT_NEAR(evidence.trend_slope, 1.0 / 3.0, 1e-9);
  EXPECT_NEAR(evidence.log_excess, std::log(2.5), 1e-9);
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpUp);
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_before, 0.030);
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_after, 0.031);
}

TEST(JumpDetectionTest, TooFewCandidateStepsGiveNoJump) {
  // Four steps: too few to tell a jump from noise by default (5).
  Sweep sweep = UpSweep({1.0e-3, 1.05e-3, 1.1e-3, 1.15e-3, 4.9e-4});
  JumpDetectionOptions options;
  EXPECT_EQ(WeighJumpEvidence(options, sweep).candidate_steps, 4);
  DetectJumps(options, &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());

  options.min_candidate_steps = 4;
  DetectJumps(options, &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 3);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpDown);
}

TEST(JumpDetectionTest, ShortSweepsHaveNoJump) {
  Sweep empty = UpSweep({});
  DetectJumps(JumpDetectionOptions(), &empty);
  EXPECT_THAT(empty.jumps, IsEmpty());
  Sweep single = UpSweep({1e-3});
  single.points[0].branch = kUp;
  DetectJumps(JumpDetectionOptions(), &single);
  EXPECT_THAT(single.jumps, IsEmpty());
  EXPECT_EQ(single.points[0].branch, kOnly);
  EXPECT_EQ(DescribeJumps(single), "F/up: no jump (1 dwells, largest a 1.0e-3)");
}

TEST(JumpDetectionTest, StepsBetweenEqualControlsAreNoCandidates) {
  // Repeated dwells at 40 Hz: a fold cannot lie between equal controls.
  Sweep sweep = FrequencySweep("R", SweepDirection::kUp, std::vector<double>(8, 40.0),
                               {1e-3, 1e-3, 1e-3, 1e-3, 5e-3, 5e-3, 5e-3, 5e-3});
  EXPECT_EQ(WeighJumpEvidence(JumpDetectionOptions(), sweep).candidate_steps, 0);
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
}

TEST(JumpDetectionTest, DetectsInEverySweepOfAList) {
  std::vector<Sweep> sweeps = {UpSweep({1.0e-3, 1.1e-3, 1.2e-3, 1.3e-3, 4.7e-3, 2.8e-4, 2.6e-4}),
                               UpSweep({1.0e-3, 1.1e-3, 1.2e-3, 1.3e-3, 1.2e-3, 1.1e-3, 1.0e-3})};
  DetectJumps(JumpDetectionOptions(), &sweeps);
  ASSERT_EQ(sweeps[0].jumps.size(), 1u);
  EXPECT_EQ(sweeps[0].jumps[0].index_before, 4);
  EXPECT_THAT(sweeps[1].jumps, IsEmpty());
}

TEST(JumpDetectionTest, DescriptionShowsEveryDigitOfTheBracketsControls) {
  Sweep sweep = FrequencySweep("F", SweepDirection::kUp,
                               {42.189, 42.192, 42.195, 42.198, 42.201, 42.204, 42.207},
                               {4.0e-3, 4.2e-3, 4.4e-3, 4.5e-3, 4.7e-3, 2.8e-4, 2.7e-4});
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_EQ(DescribeJumps(sweep),
            "F/up: jump_down between 42.201 and 42.204 Hz (a 4.7e-3 -> 2.8e-4)");
  // 161.041 and 161.012 differ at two decimals, but "161.04" is not the dwell.
  Sweep beam = FrequencySweep("L", SweepDirection::kDown,
                              {161.129, 161.1, 161.07, 161.041, 161.012, 160.982, 160.953},
                              {1.6e-4, 1.65e-4, 1.7e-4, 1.76e-4, 2.5e-4, 2.45e-4, 2.4e-4});
  DetectJumps(JumpDetectionOptions(), &beam);
  EXPECT_EQ(DescribeJumps(beam),
            "L/down: jump_up between 161.041 and 161.012 Hz (a 1.8e-4 -> 2.5e-4)");
}

TEST(JumpDetectionTest, DescriptionNotesJumpsAgainstAHardeningResponse) {
  // Going up in frequency, a hardening response jumps down; a jump up fits
  // softening. It is kept, with a note.
  Sweep soft = FrequencySweep("S", SweepDirection::kUp, {38.0, 38.1, 38.2, 38.3, 38.4, 38.5, 38.6},
                              {1.0e-3, 1.1e-3, 1.2e-3, 1.3e-3, 4.0e-3, 3.8e-3, 3.6e-3});
  DetectJumps(JumpDetectionOptions(), &soft);
  ASSERT_EQ(soft.jumps.size(), 1u);
  EXPECT_EQ(soft.jumps[0].kind, JumpKind::kJumpUp);
  EXPECT_THAT(DescribeJumps(soft),
              EndsWith("; note: a jump up going up in frequency fits a softening response (a "
                       "hardening one jumps down)"));
  // An amplitude sweep jumping down while a_base rises fits no branch of the model.
  Sweep odd = AmplitudeSweep("A", SweepDirection::kUp, 41.5,
                             {0.020, 0.022, 0.024, 0.026, 0.028, 0.030, 0.032},
                             {4.0e-3, 4.1e-3, 4.2e-3, 4.3e-3, 4.4e-3, 6e-4, 6.2e-4});
  DetectJumps(JumpDetectionOptions(), &odd);
  ASSERT_EQ(odd.jumps.size(), 1u);
  EXPECT_THAT(DescribeJumps(odd),
              EndsWith("; note: unexpected, the model jumps up as a_base rises"));
  // The directions a hardening response shows carry no note.
  Sweep hard = UpSweep({3.0e-3, 3.6e-3, 4.1e-3, 4.5e-3, 4.7e-3, 2.8e-4, 2.2e-4});
  DetectJumps(JumpDetectionOptions(), &hard);
  EXPECT_THAT(DescribeJumps(hard), Not(HasSubstr("note")));
}

// A sweep whose response is last measured high on the upper branch; the rows
// after it were recorded as missing.
Sweep SweepEndingInMissingRows() {
  Sweep sweep = FrequencySweep("H", SweepDirection::kUp, {210.0, 211.0, 212.0, 213.0, 213.055},
                               {0.9e-3, 1.0e-3, 1.1e-3, 1.2e-3, 1.2388e-3}, 0.09);
  AppendMissing(213.055, 0.09, &sweep);  // same control: cannot close the bracket
  AppendMissing(213.118, 0.09, &sweep);
  AppendMissing(213.182, 0.09, &sweep);
  return sweep;
}

TEST(JumpDetectionTest, LastDwellHighBeforeMissingRowsIsAJumpDownIntoMissingData) {
  Sweep sweep = SweepEndingInMissingRows();
  EXPECT_FALSE(WeighJumpEvidence(JumpDetectionOptions(), sweep).accepted);
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  const JumpBracket& jump = sweep.jumps[0];
  EXPECT_TRUE(jump.into_missing_data);
  EXPECT_EQ(jump.kind, JumpKind::kJumpDown);
  EXPECT_EQ(jump.index_before, 4);
  EXPECT_DOUBLE_EQ(jump.control_before, HzToRadPerSecond(213.055));
  EXPECT_DOUBLE_EQ(jump.control_after, HzToRadPerSecond(213.118));
  EXPECT_DOUBLE_EQ(jump.amplitude_before, 1.2388e-3);
  EXPECT_EQ(jump.amplitude_after, 0.0);
  // Every measured point lies before the jump down: on the upper branch.
  EXPECT_THAT(Branches(sweep), ElementsAre(kUp, kUp, kUp, kUp, kUp));
  EXPECT_EQ(DescribeJumps(sweep),
            "H/up: jump_down between 213.055 and 213.118 Hz into missing data (a 1.2e-3 -> not "
            "measured)");
}

TEST(JumpDetectionTest, NoJumpIntoMissingDataFromLowOrWithoutTrailingMissingRows) {
  // The last dwell is below the amplitude gate (0.2 of the peak).
  Sweep low = FrequencySweep("H", SweepDirection::kUp, {210.0, 211.0, 212.0, 213.0, 214.0},
                             {1.0e-3, 1.1e-3, 1.0e-3, 0.5e-3, 0.19e-3});
  AppendMissing(215.0, 0.09, &low);
  DetectJumps(JumpDetectionOptions(), &low);
  EXPECT_THAT(low.jumps, IsEmpty());

  // Missing rows only between dwells: measurements go on after them.
  Sweep middle = SweepEndingInMissingRows();
  middle.missing.clear();
  middle.points.push_back(middle.points.back());
  middle.points.back().drive_frequency_rad_s = HzToRadPerSecond(213.3);
  middle.missing.push_back({HzToRadPerSecond(213.118), 0.09, 5, 0});
  DetectJumps(JumpDetectionOptions(), &middle);
  EXPECT_THAT(middle.jumps, IsEmpty());

  // Only rows at the last dwell's own control follow it.
  Sweep same = SweepEndingInMissingRows();
  same.missing.resize(1);
  DetectJumps(JumpDetectionOptions(), &same);
  EXPECT_THAT(same.jumps, IsEmpty());
}

TEST(JumpDetectionTest, AMeasuredJumpWinsOverMissingRowsAfterIt) {
  // A down sweep that jumps up, then ends in missing rows high on the upper
  // branch: one jump per sweep, the measured one.
  Sweep sweep = FrequencySweep("F", SweepDirection::kDown, {41.0, 40.9, 40.8, 40.7, 40.6, 40.5},
                               {6e-4, 7e-4, 8e-4, 9e-4, 2.9e-3, 2.6e-3});
  AppendMissing(40.4, 0.01, &sweep);
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpUp);
  EXPECT_FALSE(sweep.jumps[0].into_missing_data);
}

// The chapter's plan (datasets/thesis-numerical/plan.yaml), simulated.
DwellPlan ThesisPlan() { return ReadDwellPlan(kSource + "/datasets/thesis-numerical/plan.yaml"); }

TEST(JumpDetectionSimulatedTest, ThesisSweepsWithOnePercentNoiseGiveExactlyTheTrueJumps) {
  DwellPlan plan = ThesisPlan();
  const std::vector<Sweep> truth = SimulateDwells(plan);
  for (std::uint64_t seed = 0; seed <= 20; ++seed) {
    plan.noise.relative_sigma = seed == 0 ? 0.0 : 0.01;
    plan.noise.seed = seed;
    std::vector<Sweep> sweeps = SimulateDwells(plan);
    DetectJumps(JumpDetectionOptions(), &sweeps);
    ASSERT_EQ(sweeps.size(), truth.size());
    for (size_t s = 0; s < sweeps.size(); ++s) {
      ASSERT_EQ(truth[s].jumps.size(), 1u) << truth[s].Name();
      ASSERT_EQ(sweeps[s].jumps.size(), 1u) << sweeps[s].Name() << " seed " << seed;
      EXPECT_EQ(sweeps[s].jumps[0].kind, truth[s].jumps[0].kind) << sweeps[s].Name();
      EXPECT_EQ(sweeps[s].jumps[0].index_before, truth[s].jumps[0].index_before)
          << sweeps[s].Name() << " seed " << seed;
    }
  }
}

TEST(JumpDetectionSimulatedTest, SmoothResonancesWithOnePercentNoiseHaveNoJump) {
  // Frequency sweeps below the onset of hysteresis (a_base 2e-4 and 5e-4 at
  // 0.1 Hz, 2e-4 at 0.02 Hz) and amplitude sweeps at 39 and 40 Hz: no fold.
  DwellPlan plan = ThesisPlan();
  plan.sweeps.clear();
  auto frequency = [&](const std::string& id, double a_base, double from, double to, double step) {
    SweepPlan sweep;
    sweep.id = id;
    sweep.kind = SweepKind::kFrequency;
    sweep.held_a_base = a_base;
    sweep.from = from;
    sweep.to = to;
    sweep.step = step;
    plan.sweeps.push_back(sweep);
  };
  auto amplitude = [&](const std::string& id, double freq_hz) {
    SweepPlan sweep;
    sweep.id = id;
    sweep.kind = SweepKind::kAmplitude;
    sweep.held_frequency_hz = freq_hz;
    sweep.from = 0.002;
    sweep.to = 0.05;
    sweep.step = 0.001;
    plan.sweeps.push_back(sweep);
  };
  frequency("F2e-4", 2e-4, 38.0, 46.0, 0.1);
  frequency("F5e-4", 5e-4, 38.0, 46.0, 0.1);
  frequency("F2e-4fine", 2e-4, 39.0, 41.0, 0.02);
  amplitude("A39", 39.0);
  amplitude("A40", 40.0);
  for (const Sweep& sweep : SimulateDwells(plan)) ASSERT_THAT(sweep.jumps, IsEmpty());
  double largest = 0.0;  // of |e| / threshold
  for (std::uint64_t seed = 0; seed <= 20; ++seed) {
    plan.noise.relative_sigma = seed == 0 ? 0.0 : 0.01;
    plan.noise.seed = seed;
    std::vector<Sweep> sweeps = SimulateDwells(plan);
    for (Sweep& sweep : sweeps) {
      const JumpEvidence evidence = WeighJumpEvidence(JumpDetectionOptions(), sweep);
      largest = std::max(largest, std::abs(evidence.log_excess) / evidence.threshold);
      DetectJumps(JumpDetectionOptions(), &sweep);
      EXPECT_THAT(sweep.jumps, IsEmpty()) << DescribeJumps(sweep) << " seed " << seed;
    }
  }
  EXPECT_LT(largest, 0.9);
}

// The measured clamped beam (datasets/clamped-beam-27C/README.md).
class MeasuredBeamJumps : public ::testing::Test {
 protected:
  void SetUp() override {
    sweeps_ = LoadSweepsCsv(kSource + "/datasets/clamped-beam-27C/sweeps.csv").sweeps;
    ASSERT_EQ(sweeps_.size(), 24u);
    for (Sweep& sweep : sweeps_) {
      evidence_.push_back(WeighJumpEvidence(JumpDetectionOptions(), sweep));
      DetectJumps(JumpDetectionOptions(), &sweep);
    }
  }
  const Sweep& Named(const std::string& name) const {
    for (const Sweep& sweep : sweeps_) {
      if (sweep.Name() == name) return sweep;
    }
    ADD_FAILURE() << "no sweep " << name;
    return sweeps_.front();
  }

  std::vector<Sweep> sweeps_;
  std::vector<JumpEvidence> evidence_;
};

TEST_F(MeasuredBeamJumps, EveryUpSweepJumpsDown) {
  for (size_t s = 0; s < sweeps_.size(); ++s) {
    const Sweep& sweep = sweeps_[s];
    if (sweep.direction != SweepDirection::kUp) continue;
    ASSERT_EQ(sweep.jumps.size(), 1u) << sweep.Name();
    const JumpBracket& jump = sweep.jumps[0];
    EXPECT_EQ(jump.kind, JumpKind::kJumpDown) << sweep.Name();
    const bool missing_after = sweep.id == "L0.090g" || sweep.id == "L0.095g";
    EXPECT_EQ(jump.into_missing_data, missing_after) << sweep.Name();
    if (!missing_after) {
      // A drop by a factor 39-148, far above the threshold.
      EXPECT_GT(jump.amplitude_before / jump.amplitude_after, 30.0) << sweep.Name();
      EXPECT_GT(std::abs(evidence_[s].log_excess), 40.0 * evidence_[s].threshold);
    }
  }
  const JumpBracket& jump = Named("L0.060g/up").jumps[0];
  EXPECT_DOUBLE_EQ(jump.control_before, HzToRadPerSecond(180.924));
  EXPECT_DOUBLE_EQ(jump.control_after, HzToRadPerSecond(180.953));
}

TEST_F(MeasuredBeamJumps, UpSweepsThatEndInZerosJumpIntoMissingData) {
  const Sweep& sweep = Named("L0.090g/up");
  EXPECT_EQ(sweep.dropped_nonpositive, 188);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  const JumpBracket& jump = sweep.jumps[0];
  EXPECT_TRUE(jump.into_missing_data);
  EXPECT_EQ(jump.index_before, static_cast<int>(sweep.points.size()) - 1);
  EXPECT_DOUBLE_EQ(jump.control_before, HzToRadPerSecond(213.055));
  EXPECT_DOUBLE_EQ(jump.control_after, HzToRadPerSecond(213.118));
  EXPECT_DOUBLE_EQ(jump.amplitude_before, 1.238802e-3);  // the sweep's largest
  EXPECT_EQ(sweep.points.front().branch, kUp);
  EXPECT_EQ(Named("L0.095g/up").jumps.at(0).into_missing_data, true);
}

TEST_F(MeasuredBeamJumps, EveryDownSweepJumpsUpAtTheTopOfItsSmearedTransition) {
  for (size_t s = 0; s < sweeps_.size(); ++s) {
    const Sweep& sweep = sweeps_[s];
    if (sweep.direction != SweepDirection::kDown) continue;
    ASSERT_EQ(sweep.jumps.size(), 1u) << sweep.Name();
    const JumpBracket& jump = sweep.jumps[0];
    EXPECT_EQ(jump.kind, JumpKind::kJumpUp) << sweep.Name();
    // The step ends at most two dwells before the sweep's largest amplitude.
    const auto peak = std::max_element(
        sweep.points.begin(), sweep.points.end(),
        [](const DwellPoint& a, const DwellPoint& b) { return a.amplitude < b.amplitude; });
    const int to_peak = static_cast<int>(peak - sweep.points.begin()) - (jump.index_before + 1);
    EXPECT_GE(to_peak, 0) << sweep.Name();
    EXPECT_LE(to_peak, 2) << sweep.Name();
    // Smeared: a factor 1.10-1.43 only, yet 1.2 thresholds or more.
    EXPECT_LT(jump.amplitude_after / jump.amplitude_before, 1.45) << sweep.Name();
    EXPECT_GT(std::abs(evidence_[s].log_excess), 1.2 * evidence_[s].threshold) << sweep.Name();
  }
  // The README's "between 161.041 and 161.012 Hz" is this pair of dwells.
  const JumpBracket& jump = Named("L0.060g/down").jumps[0];
  EXPECT_DOUBLE_EQ(jump.control_before, HzToRadPerSecond(161.041));
  EXPECT_DOUBLE_EQ(jump.control_after, HzToRadPerSecond(161.012));
  EXPECT_DOUBLE_EQ(jump.amplitude_before, 1.949221e-4);
  EXPECT_DOUBLE_EQ(jump.amplitude_after, 2.152820e-4);
}

// --- Jumps stated in the config -------------------------------------------

JumpOverride Stated(const std::string& sweep, JumpKind kind, double before_hz, double after_hz) {
  JumpOverride jump;
  jump.sweep = sweep;
  jump.kind = kind;
  jump.control = SweepKind::kFrequency;
  jump.control_before = HzToRadPerSecond(before_hz);
  jump.control_after = HzToRadPerSecond(after_hz);
  jump.line = 12;
  jump.field = "jumps[0]";
  return jump;
}

// The InputError `apply` throws; fails the test when it throws none.
template <typename Apply>
InputError ErrorOf(Apply apply) {
  try {
    apply();
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError";
  return InputError("none");
}

// A down sweep 41.0, 40.9, ..., 40.4 Hz that detection sees jump up between
// 40.7 and 40.6 Hz.
Sweep DownSweep() {
  return FrequencySweep("F", SweepDirection::kDown, {41.0, 40.9, 40.8, 40.7, 40.6, 40.5, 40.4},
                        {6e-4, 7e-4, 8e-4, 9e-4, 2.9e-3, 2.6e-3, 2.4e-3});
}

TEST(ApplyJumpOverrideTest, ReplacesTheDetectedJumpAndRelabels) {
  Sweep sweep = DownSweep();
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.at(0).index_before, 3);
  ApplyJumpOverride(Stated("F/down", JumpKind::kJumpUp, 40.8, 40.7), "beam.yaml", &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  const JumpBracket& jump = sweep.jumps[0];
  EXPECT_EQ(jump.kind, JumpKind::kJumpUp);
  EXPECT_EQ(jump.index_before, 2);
  EXPECT_DOUBLE_EQ(jump.control_before, HzToRadPerSecond(40.8));
  EXPECT_DOUBLE_EQ(jump.control_after, HzToRadPerSecond(40.7));
  EXPECT_DOUBLE_EQ(jump.amplitude_before, 8e-4);
  EXPECT_DOUBLE_EQ(jump.amplitude_after, 9e-4);
  EXPECT_TRUE(sweep.jumps_from_config);
  EXPECT_THAT(Branches(sweep), ElementsAre(kLo, kLo, kLo, kUp, kUp, kUp, kUp));
  EXPECT_EQ(DescribeJumps(sweep),
            "F/down: jump_up between 40.80 and 40.70 Hz (a 8.0e-4 -> 9.0e-4) [config]");
  // Detection again forgets it.
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_FALSE(sweep.jumps_from_config);
  EXPECT_EQ(sweep.jumps.at(0).index_before, 3);
}

TEST(ApplyJumpOverrideTest, NoneLeavesEveryDwellOnTheOnlyBranch) {
  Sweep sweep = DownSweep();
  DetectJumps(JumpDetectionOptions(), &sweep);
  JumpOverride none;
  none.sweep = "F/down";
  none.none = true;
  ApplyJumpOverride(none, "beam.yaml", &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
  EXPECT_THAT(Branches(sweep), ElementsAreArray(std::vector<Branch>(7, kOnly)));
  EXPECT_EQ(DescribeJumps(sweep), "F/down: no jump (7 dwells, largest a 2.9e-3) [config]");
}

TEST(ApplyJumpOverrideTest, BracketInsideOneIntervalKeepsTheStatedControls) {
  Sweep sweep = DownSweep();
  ApplyJumpOverride(Stated("F/down", JumpKind::kJumpUp, 40.68, 40.65), "beam.yaml", &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 3);
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_before, HzToRadPerSecond(40.68));
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_after, HzToRadPerSecond(40.65));
}

TEST(ApplyJumpOverrideTest, AmplitudeSweepTakesABaseBracket) {
  Sweep sweep = AmplitudeSweep("A", SweepDirection::kUp, 41.5, {0.030, 0.033, 0.0354, 0.036, 0.040},
                               {1.0e-3, 1.1e-3, 1.2e-3, 4.1e-3, 4.3e-3});
  JumpOverride jump;
  jump.sweep = "A/up";
  jump.kind = JumpKind::kJumpUp;
  jump.control = SweepKind::kAmplitude;
  jump.control_before = 0.0354;
  jump.control_after = 0.036;
  ApplyJumpOverride(jump, "beam.yaml", &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 2);
  EXPECT_THAT(Branches(sweep), ElementsAre(kLo, kLo, kLo, kUp, kUp));
}

TEST(ApplyJumpOverrideTest, BracketAcrossADwellNamesConfigSweepAndTheDwellInside) {
  // The pair 161.070 -> 161.012 Hz skips the dwell at 161.041 Hz.
  Sweep sweep =
      FrequencySweep("L0.060g", SweepDirection::kDown, {161.1, 161.07, 161.041, 161.012, 160.982},
                     {1.77e-4, 1.849e-4, 1.949e-4, 2.153e-4, 2.367e-4}, 0.06);
  const InputError error = ErrorOf([&] {
    ApplyJumpOverride(Stated("L0.060g/down", JumpKind::kJumpUp, 161.070, 161.012), "beam.yaml",
                      &sweep);
  });
  EXPECT_EQ(error.file(), "beam.yaml");
  EXPECT_EQ(error.line(), 12);
  EXPECT_EQ(error.field(), "jumps[0]");
  EXPECT_THAT(error.what(), HasSubstr("sweep 'L0.060g/down'"));
  EXPECT_THAT(error.what(), HasSubstr("the bracket [161.07 Hz, 161.012 Hz] does not lie between "
                                      "two consecutive dwells (dwells inside it: 161.041 Hz)"));
  EXPECT_THAT(sweep.jumps, IsEmpty());
  // The consecutive pair is accepted.
  ApplyJumpOverride(Stated("L0.060g/down", JumpKind::kJumpUp, 161.041, 161.012), "beam.yaml",
                    &sweep);
  EXPECT_EQ(sweep.jumps.at(0).index_before, 2);
}

TEST(ApplyJumpOverrideTest, BadBracketsAreInputErrors) {
  Sweep sweep = DownSweep();
  // Against the sweep's direction.
  InputError error = ErrorOf([&] {
    ApplyJumpOverride(Stated("F/down", JumpKind::kJumpUp, 40.6, 40.7), "beam.yaml", &sweep);
  });
  EXPECT_THAT(error.what(), HasSubstr("must run downward like the sweep"));
  // Beyond the sweep's last dwell.
  error = ErrorOf([&] {
    ApplyJumpOverride(Stated("F/down", JumpKind::kJumpUp, 40.3, 40.2), "beam.yaml", &sweep);
  });
  EXPECT_THAT(error.what(), HasSubstr("(the sweep runs from 41 Hz to 40.4 Hz)"));
  // A frequency bracket for an amplitude sweep.
  Sweep amplitude = AmplitudeSweep("A", SweepDirection::kUp, 41.5, {0.03, 0.04}, {1e-3, 4e-3});
  error = ErrorOf([&] {
    ApplyJumpOverride(Stated("A/up", JumpKind::kJumpUp, 40.0, 41.0), "beam.yaml", &amplitude);
  });
  EXPECT_THAT(error.what(), HasSubstr("is an amplitude sweep; give its jump as between_a_base"));
}

TEST(ApplyJumpOverrideTest, OverrideOfASweepNotInTheDataListsTheAvailableSweeps) {
  std::vector<Sweep> sweeps = {DownSweep(), UpSweep({1e-3, 2e-3})};
  const InputError error = ErrorOf([&] {
    ApplyJumpOverrides({Stated("G/down", JumpKind::kJumpUp, 40.7, 40.6)}, "beam.yaml", &sweeps);
  });
  EXPECT_EQ(error.file(), "beam.yaml");
  EXPECT_EQ(error.line(), 12);
  EXPECT_THAT(error.what(),
              HasSubstr("sweep 'G/down' is not in the data; available: F/down, F/up"));
  ApplyJumpOverrides({Stated("F/down", JumpKind::kJumpUp, 40.8, 40.7)}, "beam.yaml", &sweeps);
  EXPECT_EQ(sweeps[0].jumps.at(0).index_before, 2);
  EXPECT_THAT(sweeps[1].jumps, IsEmpty());
}

}  // namespace
}  // namespace dwellfit
