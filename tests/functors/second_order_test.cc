// The second-order model (model_form.h): its coefficients against the
// formulas of docs/model.md ("Terms beyond the chapter's"), dG/dOmega against
// finite differences of G, and the functors' Jacobians against
// ceres::GradientChecker on dwells of the second-order model near its jumps.
#include <cmath>
#include <memory>
#include <vector>

#include "ceres/gradient_checker.h"
#include "dwellfit/residuals/functors/bifurcation_range_penalty.h"
#include "dwellfit/residuals/functors/root_transition_penalty.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "gtest/gtest.h"
#include "jacobian_check.h"

namespace dwellfit {
namespace {

// Table 3.1 (docs/model.md).
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

TEST(SecondOrderModel, CoefficientsAreTheHarmonicBalanceTermsAndTheFirstOrderHasNone) {
  const double omega = HzToRadPerSecond(41.5);
  const auto first =
      ResponseCoefficients<double>::FromParameters(kFirstOrderForm, kTruth.data(), omega);
  const auto second =
      ResponseCoefficients<double>::FromParameters(kSecondOrderForm, kTruth.data(), omega);
  EXPECT_FALSE(first.higher_order);
  EXPECT_EQ(first.k6, 0.0);
  EXPECT_EQ(first.k7, 0.0);
  ASSERT_TRUE(second.higher_order);
  // k1..k4 are the chapter's, bit for bit.
  EXPECT_EQ(second.k1, first.k1);
  EXPECT_EQ(second.k2, first.k2);
  EXPECT_EQ(second.k3, first.k3);
  EXPECT_EQ(second.k4, first.k4);
  EXPECT_EQ(second.k5, 0.0);
  // g = alpha - 2 delta Omega^2, D = 9 Omega^2 - w^2 (in long double).
  const long double w = kTruth[kNaturalFrequency];
  const long double om = omega;
  const long double g = 9e8L - 2.0L * 1e4L * om * om;
  const long double d = 9.0L * om * om - w * w;
  const long double k6 = 3.0L * g * g / (32.0L * 100.0L * d);
  const long double k7 = -3.0L * 300.0L * om * g / (5.0L * 3.14159265358979323846L * 100.0L * d);
  EXPECT_NEAR(second.k6, static_cast<double>(k6), 1e-13 * std::abs(static_cast<double>(k6)));
  EXPECT_NEAR(second.k7, static_cast<double>(k7), 1e-13 * std::abs(static_cast<double>(k7)));
  // At the virtual beam's amplitudes the terms are small beside the cubic
  // ones: k6 a^4 / k4 and k7 a^3 / k2 of a few parts per thousand at 5 mm.
  const double a = 5e-3;
  EXPECT_LT(std::abs(second.k6 * a * a / second.k4), 0.01);
  EXPECT_LT(std::abs(second.k7 * a * a / second.k2), 0.01);
}

TEST(SecondOrderModel, DerivativeInDriveFrequencyMatchesCentralDifferencesOfG) {
  for (double hz : {39.0, 41.5, 43.0}) {
    for (double a : {1e-3, 4.5e-3}) {
      const double omega = HzToRadPerSecond(hz);
      const auto k =
          ResponseCoefficients<double>::FromParameters(kSecondOrderForm, kTruth.data(), omega);
      const double analytic =
          DerivativeOfGInDriveFrequency(kSecondOrderForm, kTruth.data(), omega, k, a);
      const double h = 1e-5 * omega;
      auto g = [&](double om) {
        return ResponseCoefficients<double>::FromParameters(kSecondOrderForm, kTruth.data(), om)
            .G(a);
      };
      const double numeric = (g(omega + h) - g(omega - h)) / (2.0 * h);
      EXPECT_NEAR(analytic, numeric, 1e-7 * std::abs(numeric)) << hz << " Hz, a " << a;
      // The first order's derivative differs: the new terms depend on Omega.
      const auto k1 =
          ResponseCoefficients<double>::FromParameters(kFirstOrderForm, kTruth.data(), omega);
      EXPECT_NE(DerivativeOfGInDriveFrequency(kFirstOrderForm, kTruth.data(), omega, k1, a),
                analytic);
    }
  }
}

TEST(SecondOrderModel, VerticalErrorGradientCheckerPassesOnBothBranchesNearTheJumps) {
  struct Dwell {
    double hz, a_base;
    Branch branch;
    double offset;  // relative, off the second-order branch
  };
  const std::vector<Dwell> dwells = {
      {42.2, 0.01, Branch::kUpper, 0.003},   {42.2, 0.01, Branch::kLower, -0.003},
      {40.7, 0.01, Branch::kLower, 0.002},   {40.7, 0.01, Branch::kUpper, 0.002},
      {41.5, 0.035, Branch::kLower, 0.01},   {41.5, 0.035, Branch::kUpper, 0.01},
      {41.5, 0.0069, Branch::kUpper, -0.01}, {38.0, 0.01, Branch::kOnly, 0.05}};
  for (const Dwell& d : dwells) {
    const double omega = HzToRadPerSecond(d.hz);
    const StableRoot root =
        ModelAmplitude(kSecondOrderForm, kTruth, omega, d.a_base, d.branch, 1e-3);
    ASSERT_EQ(root.status, RootStatus::kOnBranch) << d.hz << " Hz, a_base " << d.a_base;
    // The second order's root differs from the first order's by less than
    // 1 % (docs/model.md: at most 0.31 % above the integrated response).
    const double first = ModelAmplitude(kFirstOrderForm, kTruth, omega, d.a_base, d.branch, 1e-3).a;
    EXPECT_NEAR(root.a / first, 1.0, 0.01);
    for (ErrorMeasure error : {ErrorMeasure::kAbsolute, ErrorMeasure::kRelative}) {
      SCOPED_TRACE(testing::Message()
                   << d.hz << " Hz, a_base " << d.a_base << " " << BranchName(d.branch));
      const std::unique_ptr<ceres::CostFunction> cost(VerticalErrorResidual::Create(
          kSecondOrderForm, omega, d.a_base, root.a * (1.0 + d.offset), d.branch, error, 1.0));
      ExpectJacobianMatchesFiniteDifferences(*cost, kTruth, 1e-6);
    }
  }
}

TEST(SecondOrderModel, BifurcationRangePenaltyGradientCheckerPassesForBothSweepKinds) {
  // The second-order model's jump-down at a_base 0.01 and jump-up at 41.5 Hz.
  const FoldPoint down = SolveFrequencyFold(kSecondOrderForm, kTruth.data(), 0.01,
                                            JumpKind::kJumpDown, HzToRadPerSecond(42.2), 1e-3);
  const FoldPoint up = SolveAmplitudeFold(kSecondOrderForm, kTruth.data(), HzToRadPerSecond(41.5),
                                          JumpKind::kJumpUp);
  ASSERT_TRUE(down.exists);
  ASSERT_TRUE(up.exists);
  // Each fold is the second-order model's: G = a_base^2 and dG/da = 0 there.
  const auto k_down =
      ResponseCoefficients<double>::FromParameters(kSecondOrderForm, kTruth.data(), down.control);
  EXPECT_NEAR(k_down.G(down.a), 1e-4, 1e-12);
  EXPECT_NEAR(k_down.dG(down.a) * down.a / 1e-4, 0.0, 1e-9);
  const double centre = down.control;
  std::unique_ptr<ceres::CostFunction> frequency(BifurcationRangePenalty::Create(
      kSecondOrderForm, SweepKind::kFrequency, JumpKind::kJumpDown, 0.01, centre * (1 - 2e-3),
      centre * (1 + 1e-3), down.a, 10, 1.0));
  std::unique_ptr<ceres::CostFunction> amplitude(BifurcationRangePenalty::Create(
      kSecondOrderForm, SweepKind::kAmplitude, JumpKind::kJumpUp, HzToRadPerSecond(41.5),
      up.control * 0.99, up.control * 1.005, up.a, 10, 1.0));
  for (const ceres::CostFunction* cost : {frequency.get(), amplitude.get()}) {
    ceres::NumericDiffOptions numeric;
    numeric.ridders_relative_initial_step_size = 1e-5;
    const std::vector<const ceres::Manifold*>* euclidean = nullptr;
    ceres::GradientChecker checker(cost, euclidean, numeric);
    ceres::GradientChecker::ProbeResults results;
    ParameterVector p = kTruth;
    double* blocks[] = {p.data()};
    EXPECT_TRUE(checker.Probe(blocks, 1e-6, &results)) << results.error_log;
    EXPECT_GT(results.jacobians[0].norm(), 0.0);
  }
}

TEST(SecondOrderModel, RootTransitionPenaltyGradientMatchesFiniteDifferences) {
  // D = (r1 - r2)^2 of the fold pair just before the second order's
  // jump-down at a_base 0.01: its gradient against central differences.
  const FoldPoint down = SolveFrequencyFold(kSecondOrderForm, kTruth.data(), 0.01,
                                            JumpKind::kJumpDown, HzToRadPerSecond(42.2), 1e-3);
  ASSERT_TRUE(down.exists);
  const double omega = down.control * (1.0 - 1e-3);
  FoldPairSeparation s;
  ASSERT_TRUE(SeparationOfFoldPair(kSecondOrderForm, kTruth.data(), omega, 0.01, true, down.a, &s));
  EXPECT_GT(s.d, 0.0);
  for (int j = 0; j < kNumParameters; ++j) {
    ParameterVector plus = kTruth, minus = kTruth;
    const double h = 1e-6 * std::abs(kTruth[j]);
    plus[j] += h;
    minus[j] -= h;
    FoldPairSeparation sp, sm;
    ASSERT_TRUE(
        SeparationOfFoldPair(kSecondOrderForm, plus.data(), omega, 0.01, true, down.a, &sp));
    ASSERT_TRUE(
        SeparationOfFoldPair(kSecondOrderForm, minus.data(), omega, 0.01, true, down.a, &sm));
    const double numeric = (sp.d - sm.d) / (2.0 * h);
    EXPECT_NEAR(s.gradient[j] * kTruth[j], numeric * kTruth[j], 1e-4 * s.d) << ParameterName(j);
  }
}

}  // namespace
}  // namespace dwellfit
