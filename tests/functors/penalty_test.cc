#include <cmath>
#include <memory>
#include <vector>

#include "ceres/gradient_checker.h"
#include "dwellfit/residuals/functors/bifurcation_range_penalty.h"
#include "dwellfit/residuals/functors/branch_stability_penalty.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

double Evaluate(const ceres::CostFunction& cost, const ParameterVector& p,
                double* jacobian = nullptr) {
  const double* blocks[] = {p.data()};
  double* jacobians[] = {jacobian};
  double residual = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(cost.Evaluate(blocks, &residual, jacobian ? jacobians : nullptr));
  return residual;
}

void ExpectGradientCheckerPasses(const ceres::CostFunction& cost, ParameterVector p,
                                 double tolerance = 1e-6) {
  ceres::NumericDiffOptions numeric;
  numeric.ridders_relative_initial_step_size = 1e-5;
  const std::vector<const ceres::Manifold*>* euclidean = nullptr;
  ceres::GradientChecker checker(&cost, euclidean, numeric);
  ceres::GradientChecker::ProbeResults results;
  double* blocks[] = {p.data()};
  EXPECT_TRUE(checker.Probe(blocks, tolerance, &results)) << results.error_log;
  EXPECT_GT(results.jacobians[0].norm(), 0.0);
}

// The thesis case's F0.01/up jump-down bracket (42.2-42.3 Hz) and the model's
// fold inside it (42.215 Hz).
std::unique_ptr<ceres::CostFunction> FrequencyJumpDown(double before_hz, double after_hz,
                                                       int exponent = 10) {
  return std::unique_ptr<ceres::CostFunction>(BifurcationRangePenalty::Create(
      kFirstOrderForm, SweepKind::kFrequency, JumpKind::kJumpDown, 0.01,
      HzToRadPerSecond(before_hz), HzToRadPerSecond(after_hz), 4.7e-3, exponent, 1.0));
}

TEST(BifurcationRangePenalty, IsSmallInsideTheBracketAndGrowsFastOutside) {
  const double fold_hz = 42.21497;  // the model's jump-down at a_base 0.01
  // Centred on the fold: ~0. Fold at 0.3 of the half-width: 0.3^5.
  EXPECT_NEAR(Evaluate(*FrequencyJumpDown(fold_hz - 0.05, fold_hz + 0.05), kTruth), 0.0, 1e-6);
  EXPECT_NEAR(Evaluate(*FrequencyJumpDown(fold_hz - 0.065, fold_hz + 0.035), kTruth),
              std::pow(0.3, 5), 1e-3);
  // Outside by one more half-width (u = -2): 2^10 = 1024 in cost.
  const double outside = Evaluate(*FrequencyJumpDown(fold_hz + 0.05, fold_hz + 0.15), kTruth);
  EXPECT_NEAR(outside * outside, 1024.0, 1.0);
  // Exponent 2 is the plain squared distance.
  EXPECT_NEAR(Evaluate(*FrequencyJumpDown(fold_hz + 0.05, fold_hz + 0.15, 2), kTruth), -2.0, 1e-3);
}

TEST(BifurcationRangePenalty, GradientCheckerPassesForBothSweepKinds) {
  ExpectGradientCheckerPasses(*FrequencyJumpDown(42.2, 42.3), kTruth);
  std::unique_ptr<ceres::CostFunction> jump_up(BifurcationRangePenalty::Create(
      kFirstOrderForm, SweepKind::kFrequency, JumpKind::kJumpUp, 0.01, HzToRadPerSecond(40.7),
      HzToRadPerSecond(40.6), 1.1e-3, 10, 1.0));
  ExpectGradientCheckerPasses(*jump_up, kTruth);
  std::unique_ptr<ceres::CostFunction> amplitude(
      BifurcationRangePenalty::Create(kFirstOrderForm, SweepKind::kAmplitude, JumpKind::kJumpUp,
                                      HzToRadPerSecond(41.5), 0.035, 0.036, 2.0e-3, 10, 2.0));
  ExpectGradientCheckerPasses(*amplitude, kTruth);
}

TEST(BifurcationRangePenalty, MissingFoldIsLargeFiniteAndHasAUsableGradient) {
  ParameterVector damped = kTruth;
  damped[kMu1] = 20.0;  // no jump at a_base 0.01
  std::unique_ptr<ceres::CostFunction> cost = FrequencyJumpDown(42.2, 42.3);
  double jacobian[kNumParameters];
  const double residual = Evaluate(*cost, damped, jacobian);
  ASSERT_TRUE(std::isfinite(residual));
  EXPECT_GE(residual, std::pow(BifurcationRangePenalty::kNoFoldDistance, 5));
  // Less damping moves the model towards a fold: the residual falls with mu1.
  EXPECT_GT(jacobian[kMu1], 0.0);
  for (double entry : jacobian) EXPECT_TRUE(std::isfinite(entry));
  // The residual is ~1e15 here: finite differences of it carry round-off of
  // ~1e-5 relative, so the comparison is looser than on the fold.
  ExpectGradientCheckerPasses(*cost, damped, 1e-4);
}

TEST(BranchStabilityPenalty, NegligibleOnTheBranchAndExponentialPastTheFold) {
  const double omega = HzToRadPerSecond(41.5);
  const auto k =
      ResponseCoefficients<double>::FromParameters(kFirstOrderForm, kTruth.data(), omega);
  const TurningPoints tp = FindTurningPoints(k);
  ASSERT_TRUE(tp.exist);
  const double lambda = 50.0 / 5e-3;
  auto cost = [&](double a, Branch branch) {
    std::unique_ptr<ceres::CostFunction> f(
        BranchStabilityPenalty::Create(kFirstOrderForm, omega, a, branch, lambda, 1.0));
    const double r = Evaluate(*f, kTruth);
    return r * r;
  };
  // On the upper branch well above its end: exp(-Lambda * 5e-4) ~ 7e-3.
  EXPECT_NEAR(cost(tp.a_upper_end + 5e-4, Branch::kUpper), std::exp(-lambda * 5e-4), 1e-12);
  // Below the end of the upper branch (on the unstable middle branch): > 1.
  EXPECT_NEAR(cost(tp.a_upper_end - 5e-4, Branch::kUpper), std::exp(lambda * 5e-4), 1e-6);
  // The mirror for the lower branch.
  EXPECT_NEAR(cost(tp.a_lower_end - 5e-4, Branch::kLower), std::exp(-lambda * 5e-4), 1e-12);
  // Single-valued response (no turning points at 38 Hz): no cost at all.
  std::unique_ptr<ceres::CostFunction> single(BranchStabilityPenalty::Create(
      kFirstOrderForm, HzToRadPerSecond(38.0), 3e-4, Branch::kUpper, lambda, 1.0));
  EXPECT_EQ(Evaluate(*single, kTruth), 0.0);
}

TEST(BranchStabilityPenalty, GradientCheckerPassesOnBothBranches) {
  const double omega = HzToRadPerSecond(41.5);
  for (Branch branch : {Branch::kUpper, Branch::kLower}) {
    std::unique_ptr<ceres::CostFunction> cost(
        BranchStabilityPenalty::Create(kFirstOrderForm, omega, 3e-3, branch, 1e4, 1.0));
    ExpectGradientCheckerPasses(*cost, kTruth);
  }
}

}  // namespace
}  // namespace dwellfit
