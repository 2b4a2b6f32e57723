// The chapter's earlier methods at the functor level: the sextic's roots
// (amplitude_roots.h), the all-roots residual, the root-transition penalty and
// the phase-lag residuals, with their Jacobians checked by
// ceres::GradientChecker.
#include <cmath>
#include <complex>
#include <memory>
#include <vector>

#include "ceres/gradient_checker.h"
#include "dwellfit/residuals/functors/all_roots_residual.h"
#include "dwellfit/residuals/functors/phase_lag_residual.h"
#include "dwellfit/residuals/functors/root_transition_penalty.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "dwellfit/residuals/model/amplitude_roots.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "gtest/gtest.h"
#include "jacobian_check.h"

namespace dwellfit {
namespace {

ParameterVector Truth() { return {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)}; }

ResponseCoefficients<double> At(const ParameterVector& p, double hz) {
  return ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(),
                                                      HzToRadPerSecond(hz));
}

std::vector<double> Evaluate(const ceres::CostFunction& cost, ParameterVector p) {
  const double* blocks[] = {p.data()};
  std::vector<double> residuals(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(blocks, residuals.data(), nullptr));
  return residuals;
}

TEST(AmplitudeRoots, FindsTheThreeFixedPointsWhereTheResponseIsTripleValued) {
  // 42.2 Hz at a_base 0.01: just below the frequency jump-down (42.215 Hz).
  const auto k = At(Truth(), 42.2);
  const std::vector<std::complex<double>> roots = AmplitudeRoots(k, 0.01, 1e-3);
  ASSERT_EQ(roots.size(), 6u);
  const std::vector<double> real = PositiveRealRoots(k, 0.01, roots);
  ASSERT_EQ(real.size(), 3u);
  for (double a : real) EXPECT_NEAR(k.G(a), 1e-4, 1e-15);
  const StableRoot lower = SolveStableRoot(k, 0.01, Branch::kLower, 1e-3);
  const StableRoot upper = SolveStableRoot(k, 0.01, Branch::kUpper, 4e-3);
  EXPECT_NEAR(real.front(), lower.a, 1e-15);
  EXPECT_NEAR(real.back(), upper.a, 1e-15);
  EXPECT_LT(k.dG(real[1]), 0.0);  // the saddle
  // Past the fold only the lower root is left.
  EXPECT_EQ(
      PositiveRealRoots(At(Truth(), 42.3), 0.01, AmplitudeRoots(At(Truth(), 42.3), 0.01, 1e-3))
          .size(),
      1u);
}

TEST(AllRootsResidual, TakesTheStableRootNearestTheMeasurementAsTheVerticalErrorDoes) {
  const double omega = HzToRadPerSecond(42.2);
  for (double a_measured : {1.2e-3, 4.9e-3}) {
    const Branch branch = a_measured > 3e-3 ? Branch::kUpper : Branch::kLower;
    std::unique_ptr<ceres::CostFunction> all_roots(AllRootsResidual::Create(
        kFirstOrderForm, omega, 0.01, a_measured, ErrorMeasure::kAbsolute, 1.0));
    std::unique_ptr<ceres::CostFunction> vertical(VerticalErrorResidual::Create(
        kFirstOrderForm, omega, 0.01, a_measured, branch, ErrorMeasure::kAbsolute, 1.0));
    EXPECT_NEAR(Evaluate(*all_roots, Truth())[0], Evaluate(*vertical, Truth())[0], 1e-17);
    EXPECT_GT(std::abs(Evaluate(*all_roots, Truth())[0]), 1e-5);
  }
}

TEST(AllRootsResidual, GradientCheckerPassesOnEveryStableBranch) {
  struct Dwell {
    double hz, a_base, a;
  };
  for (const Dwell& d :
       {Dwell{42.2, 0.01, 4.8e-3}, Dwell{42.2, 0.01, 1.3e-3}, Dwell{38.0, 0.01, 3.5e-4},
        Dwell{41.5, 0.02, 4.2e-3}, Dwell{41.5, 0.02, 1.1e-3}}) {
    for (ErrorMeasure error : {ErrorMeasure::kAbsolute, ErrorMeasure::kRelative}) {
      SCOPED_TRACE(testing::Message() << d.hz << " Hz, a_base " << d.a_base << ", a " << d.a);
      std::unique_ptr<ceres::CostFunction> cost(AllRootsResidual::Create(
          kFirstOrderForm, HzToRadPerSecond(d.hz), d.a_base, d.a, error, 1.0));
      ExpectJacobianMatchesFiniteDifferences(*cost, Truth(), 1e-6);
    }
  }
}

// The frequency jump-down of the thesis case lies between 42.2 and 42.3 Hz
// (fold 42.2150 Hz, docs/model.md).
std::unique_ptr<ceres::CostFunction> FrequencyJumpDownPenalty(double before_hz, double after_hz) {
  return std::unique_ptr<ceres::CostFunction>(new RootTransitionPenalty(
      kFirstOrderForm, SweepKind::kFrequency, JumpKind::kJumpDown, 0.01,
      HzToRadPerSecond(before_hz), HzToRadPerSecond(after_hz), 4.7e-3, 1.0));
}

TEST(RootTransitionPenalty, IsZeroWhenTheRootsTurnComplexInsideTheBracket) {
  const std::vector<double> r = Evaluate(*FrequencyJumpDownPenalty(42.2, 42.3), Truth());
  EXPECT_EQ(r[0], 0.0);
  EXPECT_EQ(r[1], 0.0);
}

TEST(RootTransitionPenalty, PenalisesATransitionOnEitherSideOfTheBracket) {
  // Bracket above the fold: the pair is already complex before it.
  const std::vector<double> late = Evaluate(*FrequencyJumpDownPenalty(42.4, 42.5), Truth());
  EXPECT_GT(late[0], 0.0);
  EXPECT_EQ(late[1], 0.0);
  // Bracket below the fold: the pair is still real after it.
  const std::vector<double> early = Evaluate(*FrequencyJumpDownPenalty(42.0, 42.1), Truth());
  EXPECT_EQ(early[0], 0.0);
  EXPECT_GT(early[1], 0.0);
  // Farther out costs more.
  EXPECT_GT(Evaluate(*FrequencyJumpDownPenalty(42.6, 42.7), Truth())[0], late[0]);
}

TEST(RootTransitionPenalty, SeparationOfThePairChangesSignAtTheFold) {
  const FoldPoint fold =
      SolveFrequencyFold(kFirstOrderForm, Truth().data(), 0.01, JumpKind::kJumpDown,
                         HzToRadPerSecond(42.25), HzToRadPerSecond(0.1));
  ASSERT_TRUE(fold.exists);
  FoldPairSeparation below, above;
  ASSERT_TRUE(SeparationOfFoldPair(kFirstOrderForm, Truth().data(), fold.control * (1 - 1e-6), 0.01,
                                   true, 4.7e-3, &below));
  ASSERT_TRUE(SeparationOfFoldPair(kFirstOrderForm, Truth().data(), fold.control * (1 + 1e-6), 0.01,
                                   true, 4.7e-3, &above));
  EXPECT_GT(below.d, 0.0);
  EXPECT_LT(above.d, 0.0);
  EXPECT_LT(std::abs(below.d), 1e-3 * 4.7e-3 * 4.7e-3);
}

TEST(RootTransitionPenalty, GradientCheckerPassesWhereThePenaltyIsActive) {
  // Real pair after the bracket (amplitude sweep's jump-up at 41.5 Hz, fold
  // a_base 0.035358, bracket placed below it), complex pair before it
  // (frequency jump-down, bracket above the fold).
  std::unique_ptr<ceres::CostFunction> amplitude(
      new RootTransitionPenalty(kFirstOrderForm, SweepKind::kAmplitude, JumpKind::kJumpUp,
                                HzToRadPerSecond(41.5), 0.030, 0.031, 2.0e-3, 1.0));
  const std::vector<double> r = Evaluate(*amplitude, Truth());
  EXPECT_GT(r[1], 0.0);
  ExpectJacobianMatchesFiniteDifferences(*amplitude, Truth(), 1e-6);
  ExpectJacobianMatchesFiniteDifferences(*FrequencyJumpDownPenalty(42.4, 42.5), Truth(), 1e-6);
}

TEST(PhaseLagResidual, VanishesAtTheFixedPointsPhaseAndMeasuresEquations39And310) {
  const double omega = HzToRadPerSecond(41.5);
  const auto k = At(Truth(), 41.5);
  const double a = SolveStableRoot(k, 0.02, Branch::kUpper, 4e-3).a;
  const double gamma = std::atan2(k.P(a), k.Q(a));
  EXPECT_GT(gamma, 0.0);
  EXPECT_LT(gamma, kPi);
  std::unique_ptr<ceres::CostFunction> exact(
      PhaseLagResidual::Create(kFirstOrderForm, omega, 0.02, a, gamma, 1.0));
  const std::vector<double> r = Evaluate(*exact, Truth());
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
  // A phase 2 degrees late moves both balances by a_base times the rotation.
  const double bias = 2.0 * kPi / 180.0;
  std::unique_ptr<ceres::CostFunction> late(
      PhaseLagResidual::Create(kFirstOrderForm, omega, 0.02, a, gamma + bias, 1.0));
  const std::vector<double> b = Evaluate(*late, Truth());
  EXPECT_NEAR(b[0], std::sin(gamma + bias) - std::sin(gamma), 1e-12);
  EXPECT_NEAR(b[1], std::cos(gamma + bias) - std::cos(gamma), 1e-12);
  ExpectJacobianMatchesFiniteDifferences(*late, Truth(), 1e-6);
}

}  // namespace
}  // namespace dwellfit
