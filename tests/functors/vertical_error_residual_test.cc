#include "dwellfit/residuals/functors/vertical_error_residual.h"

#include <memory>
#include <vector>

#include "ceres/gradient_checker.h"
#include "dwellfit/residuals/functors/algebraic_residual.h"
#include "gtest/gtest.h"
#include "jacobian_check.h"

namespace dwellfit {
namespace {

ParameterVector Truth() { return {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)}; }

// A dwell exactly on the model's branch, then perturbed by `relative_offset`.
struct Dwell {
  double omega;
  double a_base;
  double a;
  Branch branch;
};

Dwell OnBranch(double hz, double a_base, Branch branch, double relative_offset) {
  const double omega = HzToRadPerSecond(hz);
  const StableRoot root = ModelAmplitude(kFirstOrderForm, Truth(), omega, a_base, branch, 1e-3);
  EXPECT_EQ(root.status, RootStatus::kOnBranch);
  return {omega, a_base, root.a * (1.0 + relative_offset), branch};
}

double Evaluate(const ceres::CostFunction& cost, ParameterVector p) {
  const double* blocks[] = {p.data()};
  double residual = 0.0;
  EXPECT_TRUE(cost.Evaluate(blocks, &residual, nullptr));
  return residual;
}

TEST(VerticalErrorResidual, VanishesOnTheModelCurveAndMeasuresTheVerticalDistance) {
  for (const Dwell& d :
       {OnBranch(42.2, 0.01, Branch::kUpper, 0.0), OnBranch(42.2, 0.01, Branch::kLower, 0.0)}) {
    std::unique_ptr<ceres::CostFunction> absolute(VerticalErrorResidual::Create(
        kFirstOrderForm, d.omega, d.a_base, d.a * 1.01, d.branch, ErrorMeasure::kAbsolute, 1.0));
    std::unique_ptr<ceres::CostFunction> relative(VerticalErrorResidual::Create(
        kFirstOrderForm, d.omega, d.a_base, d.a * 1.01, d.branch, ErrorMeasure::kRelative, 2.0));
    EXPECT_NEAR(Evaluate(*absolute, Truth()), 0.01 * d.a, 1e-12 * d.a);
    EXPECT_NEAR(Evaluate(*relative, Truth()), 2.0 * std::log(1.01), 1e-10);
  }
}

TEST(VerticalErrorResidual, UsesTheBranchThePointWasMeasuredOn) {
  // Same controls and measured value, two branches: two different model amplitudes.
  const Dwell upper = OnBranch(41.5, 0.02, Branch::kUpper, 0.0);
  const Dwell lower = OnBranch(41.5, 0.02, Branch::kLower, 0.0);
  std::unique_ptr<ceres::CostFunction> on_lower(
      VerticalErrorResidual::Create(kFirstOrderForm, lower.omega, lower.a_base, upper.a,
                                    Branch::kLower, ErrorMeasure::kAbsolute, 1.0));
  EXPECT_NEAR(Evaluate(*on_lower, Truth()), upper.a - lower.a, 1e-15);
}

TEST(VerticalErrorResidual, GradientCheckerPassesOnBothBranchesNearTheJumps) {
  const std::vector<Dwell> dwells = {
      // Frequency sweep at a_base = 0.01: the up-sweep's upper branch just
      // before its jump-down (42.2 Hz), the lower branch there, and the
      // down-sweep's lower branch just before its jump-up (40.7 Hz).
      OnBranch(42.2, 0.01, Branch::kUpper, 0.003),
      OnBranch(42.2, 0.01, Branch::kLower, -0.003),
      OnBranch(40.7, 0.01, Branch::kLower, 0.002),
      OnBranch(40.7, 0.01, Branch::kUpper, 0.002),
      // Amplitude sweep at 41.5 Hz near its jump-up (0.0354) and jump-down (0.0068).
      OnBranch(41.5, 0.035, Branch::kLower, 0.01),
      OnBranch(41.5, 0.035, Branch::kUpper, 0.01),
      OnBranch(41.5, 0.0069, Branch::kUpper, -0.01),
      OnBranch(41.5, 0.0069, Branch::kLower, -0.01),
      // Single-valued region far below resonance.
      OnBranch(38.0, 0.01, Branch::kOnly, 0.05),
  };
  for (const Dwell& d : dwells) {
    for (ErrorMeasure error : {ErrorMeasure::kAbsolute, ErrorMeasure::kRelative}) {
      SCOPED_TRACE(testing::Message() << "Omega " << d.omega << " a_base " << d.a_base << " branch "
                                      << BranchName(d.branch));
      std::unique_ptr<ceres::CostFunction> cost(VerticalErrorResidual::Create(
          kFirstOrderForm, d.omega, d.a_base, d.a, d.branch, error, 1.0));
      ExpectJacobianMatchesFiniteDifferences(*cost, Truth(), 1e-6);
    }
  }
}

TEST(VerticalErrorResidual, BranchEndExtensionIsContinuousAndDifferentiable) {
  // At 42.3 Hz the upper branch no longer reaches a_base = 0.01: the model
  // amplitude is the turning point where the branch ends.
  const double omega = HzToRadPerSecond(42.3);
  const auto k =
      ResponseCoefficients<double>::FromParameters(kFirstOrderForm, Truth().data(), omega);
  const TurningPoints tp = FindTurningPoints(k);
  ASSERT_TRUE(tp.exist);
  std::unique_ptr<ceres::CostFunction> cost(VerticalErrorResidual::Create(
      kFirstOrderForm, omega, 0.01, 4.8e-3, Branch::kUpper, ErrorMeasure::kAbsolute, 1.0));
  EXPECT_NEAR(Evaluate(*cost, Truth()), 4.8e-3 - tp.a_upper_end, 1e-15);
  ExpectJacobianMatchesFiniteDifferences(*cost, Truth(), 1e-6);

  // Continuity: as a_base rises through the branch end's level the residual
  // moves continuously from the turning point onto the branch.
  const double level = std::sqrt(k.G(tp.a_upper_end));
  std::unique_ptr<ceres::CostFunction> below(
      VerticalErrorResidual::Create(kFirstOrderForm, omega, level * (1 - 1e-9), 4.8e-3,
                                    Branch::kUpper, ErrorMeasure::kAbsolute, 1.0));
  std::unique_ptr<ceres::CostFunction> above(
      VerticalErrorResidual::Create(kFirstOrderForm, omega, level * (1 + 1e-9), 4.8e-3,
                                    Branch::kUpper, ErrorMeasure::kAbsolute, 1.0));
  EXPECT_NEAR(Evaluate(*below, Truth()), Evaluate(*above, Truth()), 1e-7);
}

// Each functor starts its Newton iteration from its root at the last
// evaluation. Along a path on which the upper branch at 42.2 Hz ends and comes
// back (alpha lowered and raised moves the jump-down across the dwell), and
// for the lower branch and the single-valued region, the warm-started
// residual and Jacobian equal those of a fresh functor at every point.
TEST(VerticalErrorResidual, WarmStartGivesTheColdStartValueAlongAPathAcrossAFold) {
  // The last dwell is labelled only (no jump seen) inside the bistable band,
  // measured on the upper branch: wherever the model has both roots it takes
  // the one nearer the measured amplitude, not the one it had last.
  Dwell only_in_band = OnBranch(41.5, 0.02, Branch::kUpper, 0.01);
  only_in_band.branch = Branch::kOnly;
  const std::vector<Dwell> dwells = {OnBranch(42.2, 0.01, Branch::kUpper, 0.003),
                                     OnBranch(42.2, 0.01, Branch::kLower, -0.003),
                                     OnBranch(38.0, 0.01, Branch::kOnly, 0.05), only_in_band};
  const std::vector<double> alpha_factors = {1.0, 0.99, 0.95, 0.9, 1.05, 1.3,
                                             1.0, 0.97, 0.1,  0.3, 1.0};
  for (const Dwell& d : dwells) {
    SCOPED_TRACE(BranchName(d.branch));
    std::unique_ptr<ceres::CostFunction> warm(VerticalErrorResidual::Create(
        kFirstOrderForm, d.omega, d.a_base, d.a, d.branch, ErrorMeasure::kRelative, 1.0));
    int branch_ends = 0;
    for (double factor : alpha_factors) {
      ParameterVector p = Truth();
      p[kAlpha] *= factor;
      std::unique_ptr<ceres::CostFunction> cold(VerticalErrorResidual::Create(
          kFirstOrderForm, d.omega, d.a_base, d.a, d.branch, ErrorMeasure::kRelative, 1.0));
      const double* blocks[] = {p.data()};
      double warm_residual, cold_residual;
      double warm_jacobian[kNumParameters], cold_jacobian[kNumParameters];
      double* warm_jacobians[] = {warm_jacobian};
      double* cold_jacobians[] = {cold_jacobian};
      ASSERT_TRUE(warm->Evaluate(blocks, &warm_residual, warm_jacobians));
      ASSERT_TRUE(cold->Evaluate(blocks, &cold_residual, cold_jacobians));
      EXPECT_NEAR(warm_residual, cold_residual, 1e-12) << "alpha x " << factor;
      for (int j = 0; j < kNumParameters; ++j) {
        EXPECT_NEAR(warm_jacobian[j], cold_jacobian[j], 1e-9 * std::abs(cold_jacobian[j]) + 1e-300)
            << ParameterName(j) << ", alpha x " << factor;
      }
      const StableRoot root = ModelAmplitude(kFirstOrderForm, p, d.omega, d.a_base, d.branch, d.a);
      branch_ends += root.status == RootStatus::kBranchEnd;
    }
    // The path does cross the fold for the upper branch.
    if (d.branch == Branch::kUpper) EXPECT_GT(branch_ends, 0);
  }
}

TEST(AlgebraicResidual, VanishesAtTheTruthAndPassesTheGradientChecker) {
  const Dwell d = OnBranch(41.5, 0.02, Branch::kUpper, 0.0);
  std::unique_ptr<ceres::CostFunction> exact(
      AlgebraicResidual::Create(kFirstOrderForm, d.omega, d.a_base, d.a, 1.0));
  EXPECT_NEAR(Evaluate(*exact, Truth()), 0.0, 1e-12);
  std::unique_ptr<ceres::CostFunction> off(
      AlgebraicResidual::Create(kFirstOrderForm, d.omega, d.a_base, d.a * 1.02, 1.0));
  EXPECT_GT(std::abs(Evaluate(*off, Truth())), 1e-3);
  ExpectJacobianMatchesFiniteDifferences(*off, Truth(), 1e-6);
}

TEST(VerticalErrorResidual, RejectsAnUndefinedEvaluation) {
  ParameterVector p = Truth();
  p[kEtaE] = 0.0;
  std::unique_ptr<ceres::CostFunction> cost(
      VerticalErrorResidual::Create(kFirstOrderForm, HzToRadPerSecond(41.0), 0.01, 1e-3,
                                    Branch::kUpper, ErrorMeasure::kAbsolute, 1.0));
  const double* blocks[] = {p.data()};
  double residual;
  EXPECT_FALSE(cost->Evaluate(blocks, &residual, nullptr));
}

}  // namespace
}  // namespace dwellfit
