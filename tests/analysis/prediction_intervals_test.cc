#include "dwellfit/estimator/analysis/prediction_intervals.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "gtest/gtest.h"
#include "tests/fit_test_support.h"

namespace dwellfit {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Frequency sweeps (up and down) of the thesis truth at the given base
// levels, ids "F<a_base>", from 38 to 46 Hz in 0.1 Hz steps.
std::vector<Sweep> FrequencyLevels(const std::vector<double>& a_bases, double relative_sigma) {
  DwellPlan plan;
  plan.truth = kThesisTruth;
  for (double a_base : a_bases) {
    SweepPlan sweep;
    sweep.id = "F" + std::to_string(a_base).substr(0, 5);
    sweep.kind = SweepKind::kFrequency;
    sweep.held_a_base = a_base;
    sweep.from = 38.0;
    sweep.to = 46.0;
    sweep.step = 0.1;
    plan.sweeps.push_back(sweep);
  }
  plan.noise = {relative_sigma, 7};
  std::vector<Sweep> sweeps = SimulateDwells(plan);
  if (relative_sigma > 0.0) DetectJumps(JumpDetectionOptions{}, &sweeps);
  return sweeps;
}

const Sweep& Find(const std::vector<Sweep>& sweeps, SweepDirection direction) {
  for (const Sweep& sweep : sweeps) {
    if (sweep.direction == direction) return sweep;
  }
  ADD_FAILURE() << "no sweep in that direction";
  return sweeps.front();
}

// The quantities computed independently of PredictHeldOut: the measured
// jump's fold from PredictJumps, and the mean of PredictSweep's model
// amplitudes over the upper-branch dwells.
double JumpHz(const ParameterVector& p, const Sweep& sweep) {
  for (const PredictedJump& jump : PredictJumps(kFirstOrderForm, p, sweep)) {
    if (jump.measured) return jump.exists ? RadPerSecondToHz(jump.control) : kNaN;
  }
  return kNaN;
}

double UpperBranchAmplitude(const ParameterVector& p, const Sweep& sweep) {
  const SweepPrediction prediction = PredictSweep(kFirstOrderForm, p, sweep, /*fitted=*/false);
  const std::vector<int> dwells = UpperBranchDwells(sweep);
  double sum = 0.0;
  for (int i : dwells) sum += prediction.model[i].a;
  return sum / dwells.size();
}

// s_p = sqrt(g^T C g) with g from a central difference of relative step
// 1e-4 (PredictHeldOut's: 1e-5) of the quantity `f`.
template <typename F>
double DeltaMethodSd(const ParameterVector& p, const ParameterMatrix& c, F f) {
  Eigen::Matrix<double, kNumParameters, 1> g;
  for (int j = 0; j < kNumParameters; ++j) {
    const double h = 1e-4 * std::abs(p[j]);
    ParameterVector plus = p, minus = p;
    plus[j] += h;
    minus[j] -= h;
    g[j] = (f(plus) - f(minus)) / (2.0 * h);
  }
  return std::sqrt(g.dot(c * g));
}

// The delta method on one up-sweep (jump-down and upper-branch amplitude)
// and its down-sweep (jump-up), against a finite difference of another step
// through other functions, with a covariance of 0.2 % (0.05 % for omega)
// per parameter and mu1 and alpha correlated at 0.5.
TEST(PredictionIntervals, DeltaMethodMatchesAnIndependentFiniteDifference) {
  const std::vector<Sweep> sweeps = FrequencyLevels({0.01}, 0.0);
  const Sweep& up = Find(sweeps, SweepDirection::kUp);
  const Sweep& down = Find(sweeps, SweepDirection::kDown);
  ASSERT_FALSE(UpperBranchDwells(up).empty());
  const ParameterVector& p = kThesisTruth;
  Eigen::Matrix<double, kNumParameters, 1> sd;
  for (int j = 0; j < kNumParameters; ++j) sd[j] = 2e-3 * p[j];
  sd[kNaturalFrequency] = 5e-4 * p[kNaturalFrequency];
  ParameterMatrix c = (sd * sd.transpose()).cwiseProduct(ParameterMatrix::Identity());
  c(kMu1, kAlpha) = c(kAlpha, kMu1) = 0.5 * sd[kMu1] * sd[kAlpha];
  const std::array<bool, kNumParameters> fixed{};

  const std::vector<HeldOutPrediction> on_up =
      PredictHeldOut(kFirstOrderForm, up, p, true, &c, fixed);
  ASSERT_EQ(on_up.size(), 2u);
  EXPECT_EQ(on_up[0].quantity, HeldOutQuantity::kJumpDown);
  EXPECT_EQ(on_up[1].quantity, HeldOutQuantity::kUpperBranchAmplitude);
  const auto jump_down = [&](const ParameterVector& q) { return JumpHz(q, up); };
  const auto amplitude = [&](const ParameterVector& q) { return UpperBranchAmplitude(q, up); };
  EXPECT_NEAR(on_up[0].predicted, JumpHz(p, up), 1e-9);
  EXPECT_NEAR(on_up[1].predicted, UpperBranchAmplitude(p, up), 1e-9 * on_up[1].predicted);
  const double jump_down_sd = DeltaMethodSd(p, c, jump_down);
  const double amplitude_sd = DeltaMethodSd(p, c, amplitude);
  EXPECT_GT(jump_down_sd, 0.01);  // Hz: a real uncertainty, not 0
  EXPECT_NEAR(on_up[0].parameter_sd, jump_down_sd, 1e-3 * jump_down_sd);
  EXPECT_NEAR(on_up[1].parameter_sd, amplitude_sd, 1e-3 * amplitude_sd);

  const std::vector<HeldOutPrediction> on_down =
      PredictHeldOut(kFirstOrderForm, down, p, true, &c, fixed);
  ASSERT_EQ(on_down.size(), 1u);
  EXPECT_EQ(on_down[0].quantity, HeldOutQuantity::kJumpUp);
  const double jump_up_sd =
      DeltaMethodSd(p, c, [&](const ParameterVector& q) { return JumpHz(q, down); });
  EXPECT_NEAR(on_down[0].parameter_sd, jump_up_sd, 1e-3 * jump_up_sd);

  // A fixed parameter adds nothing: alpha held, its row and column ignored.
  std::array<bool, kNumParameters> alpha_fixed{};
  alpha_fixed[kAlpha] = true;
  ParameterMatrix without_alpha = c;
  without_alpha.row(kAlpha).setZero();
  without_alpha.col(kAlpha).setZero();
  EXPECT_NEAR(PredictHeldOut(kFirstOrderForm, up, p, true, &c, alpha_fixed)[0].parameter_sd,
              DeltaMethodSd(p, without_alpha, jump_down), 1e-3 * jump_down_sd);
}

HeldOutPrediction Made(HeldOutQuantity quantity, double measured, double predicted,
                       double parameter_sd = 0.0) {
  HeldOutPrediction p;
  p.quantity = quantity;
  p.measured = measured;
  p.predicted = predicted;
  p.parameter_sd = parameter_sd;
  return p;
}

// Four levels of jump-downs (relative errors +2 %, -1 %, +4 %, none: the
// model lacks the fold) and two upper-branch amplitudes; each half-width
// and the counts worked out by hand.
TEST(PredictionIntervals, CoverageCountsEachQuantityOverTheLevels) {
  using Q = HeldOutQuantity;
  std::vector<std::vector<HeldOutPrediction>> data = {
      {Made(Q::kJumpDown, 100.0, 102.0), Made(Q::kUpperBranchAmplitude, 1.0, 0.9, 0.05)},
      {Made(Q::kJumpDown, 100.0, 99.0)},
      {Made(Q::kJumpDown, 100.0, 104.0, 1.0), Made(Q::kUpperBranchAmplitude, 2.0, 2.2)},
      {Made(Q::kJumpDown, 100.0, kNaN)}};
  std::vector<std::vector<HeldOutPrediction>*> levels;
  for (auto& level : data) levels.push_back(&level);
  const PredictionCoverage coverage = AddPredictionIntervals(levels);
  // Level 0: the others' errors -1 % and +4 %: s_m = 102 sqrt((1 + 16) / 2) % = 2.974;
  // half-width 5.83 > 2: inside.
  const double hw0 = 1.959964 * 1.02 * std::sqrt(8.5);
  EXPECT_NEAR(data[0][0].half_width, hw0, 1e-4);
  EXPECT_TRUE(data[0][0].inside);
  // Level 1: +2 % and +4 %: s_m = 99 sqrt(10) % = 3.131, half-width 6.14 > 1: inside.
  EXPECT_NEAR(data[1][0].model_sd, 0.99 * std::sqrt(10.0), 1e-9);
  EXPECT_TRUE(data[1][0].inside);
  // Level 2: +2 % and -1 %: s_m = 104 sqrt(2.5) % = 1.644, s_p = 1: half-width
  // 1.96 x 1.925 = 3.77 < 4: outside.
  const double hw2 = 1.959964 * std::hypot(1.0, 1.04 * std::sqrt(2.5));
  EXPECT_NEAR(data[2][0].half_width, hw2, 1e-4);
  EXPECT_FALSE(data[2][0].inside);
  // Level 3: no prediction, no interval, outside.
  EXPECT_TRUE(std::isnan(data[3][0].half_width));
  EXPECT_FALSE(data[3][0].inside);
  EXPECT_EQ(coverage.jump_down.inside, 2);
  EXPECT_EQ(coverage.jump_down.total, 4);
  EXPECT_NEAR(coverage.jump_down.median_half_width, hw0, 1e-4);  // of 3.77, 5.83, 6.14
  // Amplitudes: level 0 (-10 %) has the other's +10 %: s_m = 0.09, s_p = 0.05:
  // half-width 1.96 x 0.103 = 0.2017 > 0.1: inside; level 2 (+10 %): s_m = 0.22,
  // half-width 0.431 > 0.2: inside.
  EXPECT_NEAR(data[0][1].half_width, 1.959964 * std::hypot(0.05, 0.09), 1e-5);
  EXPECT_NEAR(data[2][1].half_width, 1.959964 * 0.22, 1e-5);
  EXPECT_EQ(coverage.upper_branch.inside, 2);
  EXPECT_EQ(coverage.upper_branch.total, 2);
  EXPECT_NEAR(coverage.upper_branch.median_half_width_percent,
              0.5 * (100.0 * 1.959964 * std::hypot(0.05, 0.09) / 0.9 + 100.0 * 1.959964 * 0.1),
              1e-3);
  EXPECT_EQ(coverage.jump_up.total, 0);
  EXPECT_TRUE(std::isnan(coverage.jump_up.median_half_width));
}

// The validation intervals of a fit: the sweeps grouped into levels by id,
// every measured jump and upper branch predicted with a parameter
// uncertainty from the fit's covariance, each level's model error from the
// other levels only.
TEST(PredictionIntervals, ValidationSweepsAreGroupedIntoLevels) {
  const std::vector<Sweep> fitted_sweeps = SimulateDataset(kThesisTruth, 0.01, 3);
  const std::vector<Sweep> validation_sweeps = FrequencyLevels({0.008, 0.012, 0.014}, 0.01);
  IdentificationOptions options;
  options.initial = kThesisTruth;
  const ValidationIntervals v = PredictValidationIntervals(
      Pointers(fitted_sweeps), Pointers(validation_sweeps), options, kThesisTruth, true);
  EXPECT_TRUE(v.parameter_covariance) << v.note;
  ASSERT_EQ(v.levels.size(), 3u);
  EXPECT_EQ(v.levels[0].level, validation_sweeps[0].id);
  for (std::size_t level = 0; level < v.levels.size(); ++level) {
    ASSERT_EQ(v.levels[level].predictions.size(), 3u);  // jump-down, amplitude, jump-up
    for (const HeldOutPrediction& p : v.levels[level].predictions) {
      EXPECT_GT(p.parameter_sd, 0.0);
      if (p.quantity == HeldOutQuantity::kUpperBranchAmplitude) continue;
      EXPECT_NEAR(p.predicted, p.measured, 0.1) << p.sweep;  // the truth's fold in its bracket
      // s_m from the other two levels' relative errors of the same quantity.
      double sum = 0.0;
      for (std::size_t other = 0; other < v.levels.size(); ++other) {
        if (other == level) continue;
        for (const HeldOutPrediction& q : v.levels[other].predictions) {
          if (q.quantity == p.quantity) sum += std::pow((q.predicted - q.measured) / q.measured, 2);
        }
      }
      EXPECT_NEAR(p.model_sd, p.predicted * std::sqrt(sum / 2.0), 1e-12);
    }
  }
  EXPECT_EQ(v.coverage.jump_down.total, 3);
  EXPECT_EQ(v.coverage.jump_up.total, 3);
  EXPECT_EQ(v.coverage.upper_branch.total, 3);
  // No usable fit: every prediction missing, counted outside.
  const ValidationIntervals none = PredictValidationIntervals(
      Pointers(fitted_sweeps), Pointers(validation_sweeps), options, kThesisTruth, false);
  EXPECT_EQ(none.coverage.jump_down.inside, 0);
  EXPECT_FALSE(none.parameter_covariance);
  EXPECT_FALSE(none.note.empty());
}

}  // namespace
}  // namespace dwellfit
