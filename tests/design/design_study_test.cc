// design_study: the standard arm dwells where the plan says, the closed
// loop's test time is the rig's own settling and recording time, simultaneous
// intervals widen every half-width by their quantile, and the same seed gives
// the same study.
#include "dwellfit/estimator/design/design_study.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/block_covariance.h"
#include "dwellfit/estimator/common/input_error.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kVirtualBeam = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/virtual-beam";

DesignStudyCase VirtualBeam() {
  return LoadDesignStudyCase("virtual-beam", kVirtualBeam + "/beam.yaml",
                             kVirtualBeam + "/plan.yaml", kVirtualBeam + "/rig.yaml");
}

TEST(DesignStudy, TruthOfTheVirtualBeamIsTable31s) {
  const std::array<double, kStudyQuantities> truth = StudyTruth(VirtualBeam());
  // alpha - (2/3) delta (2 pi 41.5)^2 = 9e8 - (2/3) 1e4 (260.752...)^2 = 4.4672e8.
  EXPECT_NEAR(truth[kStudyAlphaE], 9.0e8 - (2.0 / 3.0) * 1.0e4 * std::pow(2 * M_PI * 41.5, 2), 1.0);
  EXPECT_NEAR(truth[kStudyAlphaE], 4.4672e8, 1e4);
  EXPECT_DOUBLE_EQ(truth[kStudyEtaE], 100.0);
  EXPECT_DOUBLE_EQ(truth[kStudyOmega], 2 * M_PI * 40.0);
  EXPECT_DOUBLE_EQ(truth[kStudyMu1], 0.2);
}

// A member of the family (model_form.h) is refused: next_dwell's ranking and
// the study's quantities are the chapter's terms'.
TEST(DesignStudy, AFamilyMembersPlanIsRefusedNamingTheModelKey) {
  std::ifstream in(kVirtualBeam + "/plan.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string plan = text.str();
  plan.replace(plan.find("  mu2: 300"), 10, "  mu3: 1.0e5");
  const std::string path = ::testing::TempDir() + "/member_plan.yaml";
  std::ofstream(path) << plan << "model: {damping: cubic}\n";
  try {
    LoadDesignStudyCase("member", kVirtualBeam + "/beam.yaml", path, kVirtualBeam + "/rig.yaml");
    FAIL() << "a member's plan was taken";
  } catch (const InputError& error) {
    EXPECT_EQ(error.file(), path);
    EXPECT_NE(std::string(error.what()).find("chapter's terms"), std::string::npos) << error.what();
  }
}

TEST(DesignStudy, StandardArmDwellsAtThePlansFrequenciesAndLevels) {
  DesignStudyCase study = VirtualBeam();
  // A short plan: 38 to 46 Hz by 1 Hz at level 0.01, up then down, then
  // levels 0.01 to 0.05 by 0.01 at 41.5 Hz, up then down.
  study.plan.sweeps.resize(2);
  study.plan.sweeps[0].step = 1.0;
  study.plan.sweeps[1].from = 0.01;
  study.plan.sweeps[1].step = 0.01;
  DesignStudyOptions options;
  options.target.relative_half_width = {1e-9, 1e-9, 1e-9, 1e-9};  // never met
  options.time_budget_seconds = 900.0;  // a pass takes about 28 x 20 s: more than one pass
  std::vector<std::pair<double, double>> expected;
  for (int f = 38; f <= 46; ++f) expected.push_back({f, 0.01});
  for (int f = 46; f >= 38; --f) expected.push_back({f, 0.01});
  for (int i = 1; i <= 5; ++i) expected.push_back({41.5, 0.01 * i});
  for (int i = 5; i >= 1; --i) expected.push_back({41.5, 0.01 * i});
  const ArmRun arm = RunStandardProtocol(study, options, 7);
  EXPECT_FALSE(arm.reached);
  EXPECT_EQ(arm.end, "time budget spent");
  ASSERT_GE(arm.dwells.size(), expected.size());
  for (std::size_t i = 0; i < arm.dwells.size(); ++i) {
    const auto& [f, level] = expected[i % expected.size()];
    EXPECT_NEAR(arm.dwells[i].frequency_hz, f, 1e-9) << "dwell " << i;
    EXPECT_NEAR(arm.dwells[i].level, level, 1e-12) << "dwell " << i;
  }
  // The budget is checked before every dwell: the last one starts within it.
  EXPECT_GE(arm.elapsed_seconds, options.time_budget_seconds);
  const StudyDwell& last = arm.dwells.back();
  EXPECT_LT(arm.elapsed_seconds - last.settle_seconds - last.record_seconds,
            options.time_budget_seconds);
  // One fit after each sweep direction.
  EXPECT_EQ(arm.fits[0].dwells, 9);
  EXPECT_EQ(arm.fits[1].dwells, 18);
  EXPECT_EQ(arm.fits[2].dwells, 23);
  EXPECT_EQ(arm.fits[3].dwells, 28);
}

// Replays the arm's dwells on a fresh rig of the same seed, at rest before
// each start sweep as the loop does: the same settling and recording times,
// whose sum is the arm's test time.
TEST(DesignStudy, ClosedLoopTimeIsTheRigsSettlingAndRecordingTime) {
  const DesignStudyCase study = VirtualBeam();
  DesignStudyOptions options;
  options.time_budget_seconds = 800.0;  // the start (27 dwells, ~720 s) and a few more
  const ArmRun arm = RunClosedLoop(study, options, 3);
  ASSERT_GT(arm.dwells.size(), 28u);
  RigOptions rig_options = study.rig;
  rig_options.noise_seed = 3;
  VirtualRig rig(study.plan.truth, rig_options);
  double sum = 0.0, sum_to_target = 0.0;
  std::string previous;
  for (std::size_t i = 0; i < arm.dwells.size(); ++i) {
    const StudyDwell& d = arm.dwells[i];
    if (d.sweep != previous && d.sweep.find("/start-") != std::string::npos) rig.Rest();
    previous = d.sweep;
    const RigDwell replay = rig.Dwell(d.frequency_hz, d.level);
    EXPECT_DOUBLE_EQ(replay.settle_seconds, d.settle_seconds) << "dwell " << i;
    EXPECT_DOUBLE_EQ(replay.record_seconds, d.record_seconds) << "dwell " << i;
    sum += replay.settle_seconds + replay.record_seconds;
    if (static_cast<int>(i) < arm.dwells_to_target) sum_to_target = sum;
  }
  EXPECT_NEAR(arm.elapsed_seconds, sum, 1e-9 * sum);
  EXPECT_NEAR(arm.elapsed_seconds, rig.elapsed_seconds(), 1e-9 * sum);
  EXPECT_GE(arm.elapsed_seconds, options.time_budget_seconds);
  if (arm.reached) EXPECT_NEAR(arm.time_to_target_seconds, sum_to_target, 1e-9 * sum);
  // Every fit after the start's is made after one more dwell.
  for (std::size_t k = 1; k < arm.fits.size(); ++k) {
    EXPECT_EQ(arm.fits[k].dwells, arm.fits[k - 1].dwells + 1);
  }
}

// Simultaneous intervals: the same loop (a target never met, so that the
// path cannot depend on the intervals' width), every half-width wider by
// t_{(1 + 0.95^(1/4))/2, n-6} / t_{0.975, n-6}, n the fit's dwells and six
// parameters free.
TEST(DesignStudy, SimultaneousIntervalsWidenEveryHalfWidthByTheirQuantile) {
  const DesignStudyCase study = VirtualBeam();
  DesignStudyOptions options;
  options.time_budget_seconds = 760.0;
  options.target.relative_half_width = {1e-9, 1e-9, 1e-9, 1e-9};
  options.target.simultaneous = false;
  const ArmRun each = RunClosedLoop(study, options, 2);
  options.target.simultaneous = true;
  const ArmRun joint = RunClosedLoop(study, options, 2);
  ASSERT_EQ(each.fits.size(), joint.fits.size());
  int compared = 0;
  for (std::size_t k = 0; k < each.fits.size(); ++k) {
    const StudyFit& e = each.fits[k];
    const StudyFit& j = joint.fits[k];
    ASSERT_EQ(e.has_intervals, j.has_intervals);
    if (!e.has_intervals) continue;
    const int dof = e.dwells - kNumParameters;
    EXPECT_DOUBLE_EQ(e.interval_quantile, IntervalQuantile(false, dof));
    EXPECT_DOUBLE_EQ(j.interval_quantile, SimultaneousIntervalQuantile(false, dof, 4));
    for (int i = 0; i < kStudyQuantities; ++i) {
      EXPECT_DOUBLE_EQ(e.value[i], j.value[i]);
      EXPECT_NEAR(j.half_width[i] / e.half_width[i], j.interval_quantile / e.interval_quantile,
                  1e-12);
    }
    ++compared;
  }
  EXPECT_GE(compared, 2);
}

TEST(DesignStudy, SameSeedSameStudyAnotherSeedAnother) {
  const DesignStudyCase study = VirtualBeam();
  DesignStudyOptions options;
  options.seeds = 1;
  options.time_budget_seconds = 760.0;
  auto csv = [&](std::uint64_t seed) {
    options.first_seed = seed;
    const DesignStudyResult result = RunDesignStudy(study, options, nullptr);
    return DesignStudyCsv({result}) + DesignStudyDwellsCsv({result}) + DesignStudyFitsCsv({result});
  };
  const std::string first = csv(5);
  EXPECT_EQ(first, csv(5));
  EXPECT_NE(first, csv(6));
}

TEST(DesignStudy, MedianOfOddAndEvenCounts) {
  EXPECT_DOUBLE_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4.0, 1.0, 2.0, 3.0}), 2.5);
  EXPECT_TRUE(std::isnan(Median({})));
}

TEST(DesignStudy, OptionsOutOfRangeAreRefusedNamingTheField) {
  DesignStudyOptions options;
  std::string error;
  options.target.relative_half_width[kStudyMu1] = 0.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("mu1"), std::string::npos) << error;
  options = DesignStudyOptions();
  options.seeds = 0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(RunDesignStudy(VirtualBeam(), options, nullptr), InputError);
}

}  // namespace
}  // namespace dwellfit
