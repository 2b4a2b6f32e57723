#include "estimator/jump_detection.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "estimator/identification_options.h"
#include "residuals/model_parameters.h"

namespace dwellfit {
namespace {

using ::testing::ElementsAre;
using ::testing::ElementsAreArray;
using ::testing::IsEmpty;

constexpr Branch kLo = Branch::kLower;
constexpr Branch kUp = Branch::kUpper;
constexpr Branch kOnly = Branch::kOnly;

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
  Sweep sweep = AmplitudeSweep("A", SweepDirection::kUp, 41.5, {0.030, 0.033, 0.0354, 0.036, 0.040},
                               {1.0e-3, 1.1e-3, 1.2e-3, 4.1e-3, 4.3e-3});
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  const JumpBracket& jump = sweep.jumps[0];
  EXPECT_EQ(jump.kind, JumpKind::kJumpUp);
  EXPECT_EQ(jump.index_before, 2);
  EXPECT_DOUBLE_EQ(jump.control_before, 0.0354);  // a_base, not a frequency
  EXPECT_DOUBLE_EQ(jump.control_after, 0.036);
  EXPECT_THAT(Branches(sweep), ElementsAre(kLo, kLo, kLo, kUp, kUp));
  EXPECT_EQ(DescribeJumps(sweep),
            "A/up: jump_up between a_base 0.0354 and 0.036 (a 1.2e-3 -> 4.1e-3)");
}

TEST(JumpDetectionTest, AmplitudeSweepDownJumpsDownInABase) {
  Sweep sweep = AmplitudeSweep("A", SweepDirection::kDown, 41.5, {0.010, 0.008, 0.0068, 0.006},
                               {3.5e-3, 3.2e-3, 3.0e-3, 6e-4});
  DetectJumps(JumpDetectionOptions(), &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].kind, JumpKind::kJumpDown);
  EXPECT_EQ(sweep.jumps[0].index_before, 2);
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_before, 0.0068);
  EXPECT_DOUBLE_EQ(sweep.jumps[0].control_after, 0.006);
  EXPECT_THAT(Branches(sweep), ElementsAre(kUp, kUp, kUp, kLo));
}

TEST(JumpDetectionTest, SmoothResonanceHasNoJumpAndEveryPointOnOnlyBranch) {
  // Largest step ratio 1e-3 / 6e-4 = 1.67 < 2.
  Sweep sweep = UpSweep({1e-4, 2e-4, 3.5e-4, 6e-4, 1e-3, 6e-4, 3.5e-4, 2e-4});
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
  EXPECT_THAT(Branches(sweep), ElementsAreArray(std::vector<Branch>(8, kOnly)));
  EXPECT_EQ(DescribeJumps(sweep), "F/up: no jump (8 dwells, largest a 1.0e-3)");
}

TEST(JumpDetectionTest, NoiseFloorHopFarBelowThePeakIsIgnored) {
  // 1e-6 -> 3e-6 is a ratio-3 hop, but 3e-6 < 0.2 * 1e-3; every other step
  // has ratio < 2.
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

TEST(JumpDetectionTest, RatioMustExceedMinRatio) {
  // The step 1.1e-3 -> 4.4e-4 has ratio 2.5.
  const std::vector<double> amplitudes = {1e-3, 1.1e-3, 4.4e-4, 4e-4};
  JumpDetectionOptions options;
  options.min_ratio = 2.4;
  Sweep sweep = UpSweep(amplitudes);
  DetectJumps(options, &sweep);
  ASSERT_EQ(sweep.jumps.size(), 1u);
  EXPECT_EQ(sweep.jumps[0].index_before, 1);

  options.min_ratio = 2.6;
  DetectJumps(options, &sweep);
  EXPECT_THAT(sweep.jumps, IsEmpty());
  // Labels from the earlier detection are reset too.
  EXPECT_THAT(Branches(sweep), ElementsAre(kOnly, kOnly, kOnly, kOnly));
}

TEST(JumpDetectionTest, LargerSideMustReachMinRelativeAmplitude) {
  // The only step above ratio 2 is 3e-4 -> 1e-4, whose larger side is 0.3 of
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

TEST(JumpDetectionTest, DetectsInEverySweepOfAList) {
  std::vector<Sweep> sweeps = {UpSweep({1e-3, 4.7e-3, 2.8e-4}), UpSweep({1e-3, 1.2e-3})};
  DetectJumps(JumpDetectionOptions(), &sweeps);
  ASSERT_EQ(sweeps[0].jumps.size(), 1u);
  EXPECT_EQ(sweeps[0].jumps[0].index_before, 1);
  EXPECT_THAT(sweeps[1].jumps, IsEmpty());
}

TEST(JumpDetectionTest, DescriptionShowsEnoughDigitsToSeparateTheBracket) {
  Sweep sweep =
      FrequencySweep("F", SweepDirection::kUp, {42.198, 42.201, 42.204}, {4.5e-3, 4.7e-3, 2.8e-4});
  DetectJumps(JumpDetectionOptions(), &sweep);
  EXPECT_EQ(DescribeJumps(sweep),
            "F/up: jump_down between 42.201 and 42.204 Hz (a 4.7e-3 -> 2.8e-4)");
}

}  // namespace
}  // namespace dwellfit
