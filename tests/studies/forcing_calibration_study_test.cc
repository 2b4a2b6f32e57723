// The per-sweep natural frequency on the measured beam (docs/results.md): fitted on
// L0.060g and L0.080g as beam.yaml does, the ten held-out levels' jump-down and
// upper-branch medians meet 2.0 % and 8 % together with a w per sweep, and not
// with one shared w. The errors are against the measured jumps and amplitudes.
#include "dwellfit/estimator/studies/forcing_calibration_study.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"

namespace dwellfit {
namespace {

TEST(ForcingCalibrationStudy, ANaturalFrequencyPerSweepPredictsTheMeasuredBeam) {
  const IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C/beam.yaml");
  ForcingCalibrationOptions calibration;
  calibration.parameter = CalibratedParameter::kNaturalFrequency;
  calibration.held_out_dwells = HeldOutDwells::kBelowHalfPeak;
  const ForcingCalibrationComparison c = CompareForcingCalibration(config, calibration);
  ASSERT_TRUE(c.with.fit.IsSolutionUsable()) << c.with.fit.message;
  EXPECT_TRUE(c.notes.empty()) << c.notes.front();
  ASSERT_EQ(c.errors_with.size(), 20u);  // ten levels, up and down
  const double jump_without = MedianAbsoluteError(c.errors_without, true);
  const double upper_without = MedianAbsoluteError(c.errors_without, false);
  const double jump_with = MedianAbsoluteError(c.errors_with, true);
  const double upper_with = MedianAbsoluteError(c.errors_with, false);
  EXPECT_GT(jump_without, 2.0);  // one shared w misses the jump-down bar
  EXPECT_LE(jump_with, 2.0);
  EXPECT_LE(upper_with, 8.0);
  EXPECT_LT(upper_with, upper_without);
  // The held-out w's scales are near 1: a few per cent, not a free fit.
  for (const HeldOutSweepErrors& e : c.errors_with) {
    EXPECT_NEAR(e.scale, 1.0, 0.05) << e.sweep;
  }
}

// Leave-one-level-out over the twelve levels of beam-selected.yaml (the model
// select_model recommends), folds as select_model's `training: config` makes
// them: the fold of L0.060g (a fitted level) fits L0.055g and L0.080g, the
// nearest unfitted level in its place, and is CompareForcingCalibration of
// that config; with a w per sweep the medians meet 2.0 % and 8 % together,
// with one shared w the jump-down's does not.
TEST(ForcingCalibrationStudy, LeaveOneLevelOutMeetsTheBarsOnlyWithAFrequencyPerSweep) {
  const IdentifyConfig config = LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) +
                                                   "/datasets/clamped-beam-27C/beam-selected.yaml");
  ForcingCalibrationOptions calibration;
  calibration.parameter = CalibratedParameter::kNaturalFrequency;
  calibration.held_out_dwells = HeldOutDwells::kBelowHalfPeak;
  const std::vector<LevelOutErrors> folds = LeaveOneLevelOut(config, calibration);
  ASSERT_EQ(folds.size(), 12u);
  EXPECT_EQ(folds.front().level, "L0.040g");  // data order
  std::vector<HeldOutSweepErrors> without, with;
  const LevelOutErrors* l060 = nullptr;
  for (const LevelOutErrors& fold : folds) {
    EXPECT_TRUE(fold.notes.empty()) << fold.level << ": " << fold.notes.front();
    ASSERT_EQ(fold.with.size(), 2u) << fold.level;  // up and down
    without.insert(without.end(), fold.without.begin(), fold.without.end());
    with.insert(with.end(), fold.with.begin(), fold.with.end());
    if (fold.level == "L0.060g") l060 = &fold;
  }
  ASSERT_NE(l060, nullptr);
  IdentifyConfig by_hand = config;
  by_hand.fit_sweeps = {{"L0.055g", std::nullopt}, {"L0.080g", std::nullopt}};
  by_hand.validate_sweeps = {{"L0.060g", std::nullopt}};
  const ForcingCalibrationComparison c = CompareForcingCalibration(by_hand, calibration);
  ASSERT_EQ(c.errors_with.size(), 2u);
  const auto same = [](double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; };
  for (int v = 0; v < 2; ++v) {
    EXPECT_EQ(l060->with[v].sweep, c.errors_with[v].sweep);
    EXPECT_TRUE(same(l060->with[v].jump_down_percent, c.errors_with[v].jump_down_percent)) << v;
    EXPECT_TRUE(same(l060->with[v].upper_branch_percent, c.errors_with[v].upper_branch_percent))
        << v;
    EXPECT_TRUE(same(l060->without[v].jump_down_percent, c.errors_without[v].jump_down_percent))
        << v;
  }
  EXPECT_TRUE(std::isfinite(l060->with[0].jump_down_percent));  // the up sweep's
  EXPECT_GT(MedianAbsoluteError(without, true), 2.0);
  EXPECT_LE(MedianAbsoluteError(with, true), 2.0);
  EXPECT_LE(MedianAbsoluteError(with, false), 8.0);
}

}  // namespace
}  // namespace dwellfit
