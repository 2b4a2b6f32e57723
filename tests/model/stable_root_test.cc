#include "dwellfit/residuals/model/stable_root.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <type_traits>

#include "ceres/jet.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// Table 3.1 truth with w = 2 pi 40 rad/s (docs/model.md).
ParameterVector Truth() { return {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)}; }

ResponseCoefficients<double> At(double hz) {
  const ParameterVector p = Truth();
  return ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(),
                                                      HzToRadPerSecond(hz));
}

// The coefficients (3.3) formed from the parameters' terms (as a batch of
// dwells forms them) are, bit for bit, those of the equations written out, in
// double and with Jets carrying the derivatives.
template <typename T>
void ExpectCoefficientsOfEquations(const T* p, double omega) {
  const ResponseCoefficients<T> k =
      ResponseCoefficients<T>::FromParameters(kFirstOrderForm, p, omega);
  const ResponseCoefficients<T> shared =
      ResponseCoefficients<T>::FromTerms(ParameterTerms<T>(kFirstOrderForm, p), omega);
  const T& eta_e = p[kEtaE];
  const T& w = p[kNaturalFrequency];
  const T written[] = {omega * p[kMu1] / eta_e, (4.0 / (3.0 * kPi)) * p[kMu2] * omega / eta_e,
                       -(omega * omega - w * w) / (2.0 * eta_e),
                       (3.0 * p[kAlpha] - 2.0 * p[kDelta] * omega * omega) / (8.0 * eta_e)};
  const T formed[] = {k.k1, k.k2, k.k3, k.k4};
  const T formed_shared[] = {shared.k1, shared.k2, shared.k3, shared.k4};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(ScalarPart(formed[i]), ScalarPart(written[i])) << "k" << i + 1;
    EXPECT_EQ(ScalarPart(formed_shared[i]), ScalarPart(written[i])) << "k" << i + 1;
    if constexpr (!std::is_same_v<T, double>) {
      for (int j = 0; j < kNumParameters; ++j) {
        EXPECT_EQ(formed[i].v[j], written[i].v[j]) << "k" << i + 1 << " d/dp" << j;
        EXPECT_EQ(formed_shared[i].v[j], written[i].v[j]) << "k" << i + 1 << " d/dp" << j;
      }
    }
  }
}

TEST(ResponseCoefficients, FromTheParametersTermsAreTheEquationsBitForBit) {
  const ParameterVector p = {104.0, 0.19, 310.0, 1.1e4, 9.3e8, HzToRadPerSecond(40.1)};
  std::array<ceres::Jet<double, kNumParameters>, kNumParameters> jets;
  for (int j = 0; j < kNumParameters; ++j) jets[j] = ceres::Jet<double, kNumParameters>(p[j], j);
  for (double hz : {38.0, 40.0, 41.37, 46.0}) {
    ExpectCoefficientsOfEquations(p.data(), HzToRadPerSecond(hz));
    ExpectCoefficientsOfEquations(jets.data(), HzToRadPerSecond(hz));
  }
}

TEST(FindTurningPoints, AmplitudeSweepJumpLevelsAt41_5HzMatchTheChapter) {
  const auto k = At(41.5);
  const TurningPoints tp = FindTurningPoints(k);
  ASSERT_TRUE(tp.exist);
  EXPECT_LT(tp.a_lower_end, tp.a_upper_end);
  EXPECT_NEAR(k.dG(tp.a_lower_end), 0.0, 1e-12);
  EXPECT_NEAR(k.dG(tp.a_upper_end), 0.0, 1e-12);
  // docs/model.md: jumps up near a_base = 0.0354 and down near 0.0068.
  EXPECT_NEAR(std::sqrt(k.G(tp.a_lower_end)), 0.0354, 0.0005);
  EXPECT_NEAR(std::sqrt(k.G(tp.a_upper_end)), 0.0068, 0.0002);
  EXPECT_GT(k.d2G(tp.a_upper_end), 0.0);  // a local minimum of G
  EXPECT_LT(k.d2G(tp.a_lower_end), 0.0);  // a local maximum of G
}

TEST(FindTurningPoints, NoFoldFarBelowResonance) {
  EXPECT_FALSE(FindTurningPoints(At(38.0)).exist);
}

TEST(SolveStableRoot, FrequencySweepBranchesEndWhereTheChapterSays) {
  const double a_base = 0.01;
  // Going up: the upper branch still exists at 42.2 Hz and is gone at 42.3 Hz.
  // (the fold is at 42.215 Hz, docs/model.md; a brute-force root count of
  // G(a) puts three roots at 42.2 Hz and one at 42.25 Hz.)
  EXPECT_EQ(SolveStableRoot(At(42.2), a_base, Branch::kUpper, 4e-3).status, RootStatus::kOnBranch);
  EXPECT_EQ(SolveStableRoot(At(42.3), a_base, Branch::kUpper, 4e-3).status, RootStatus::kBranchEnd);
  // Coming down: the lower branch exists at 40.7 Hz and is gone at 40.6 Hz.
  EXPECT_EQ(SolveStableRoot(At(40.7), a_base, Branch::kLower, 1e-3).status, RootStatus::kOnBranch);
  EXPECT_EQ(SolveStableRoot(At(40.6), a_base, Branch::kLower, 1e-3).status, RootStatus::kBranchEnd);
}

TEST(SolveStableRoot, ReturnsTheStableRootOfTheNamedBranchFromAnyGuess) {
  const auto k = At(41.5);
  const double a_base = 0.02;  // inside the bistable range (0.0068, 0.0354)
  const TurningPoints tp = FindTurningPoints(k);
  for (double guess : {1e-6, 1e-4, 1e-3, 3e-3, 1e-2, 1.0}) {
    const StableRoot lower = SolveStableRoot(k, a_base, Branch::kLower, guess);
    const StableRoot upper = SolveStableRoot(k, a_base, Branch::kUpper, guess);
    ASSERT_EQ(lower.status, RootStatus::kOnBranch);
    ASSERT_EQ(upper.status, RootStatus::kOnBranch);
    EXPECT_NEAR(k.G(lower.a) / (a_base * a_base), 1.0, 1e-12);
    EXPECT_NEAR(k.G(upper.a) / (a_base * a_base), 1.0, 1e-12);
    EXPECT_GT(k.dG(lower.a), 0.0);
    EXPECT_GT(k.dG(upper.a), 0.0);
    EXPECT_LT(lower.a, tp.a_lower_end);
    EXPECT_GT(upper.a, tp.a_upper_end);
  }
}

TEST(SolveStableRoot, OnlyPicksTheStableRootNearestTheMeasurement) {
  const auto k = At(41.5);
  const double a_base = 0.02;
  const double lower = SolveStableRoot(k, a_base, Branch::kLower, 1e-3).a;
  const double upper = SolveStableRoot(k, a_base, Branch::kUpper, 1e-3).a;
  EXPECT_DOUBLE_EQ(SolveStableRoot(k, a_base, Branch::kOnly, lower * 1.1).a, lower);
  EXPECT_DOUBLE_EQ(SolveStableRoot(k, a_base, Branch::kOnly, upper * 0.9).a, upper);
}

TEST(SolveStableRoot, FailsCleanlyOnNonFiniteParameters) {
  ParameterVector p = Truth();
  p[kEtaE] = 0.0;
  const auto k = ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(),
                                                              HzToRadPerSecond(41.0));
  EXPECT_EQ(SolveStableRoot(k, 0.01, Branch::kUpper, 1e-3).status, RootStatus::kFailed);
}

}  // namespace
}  // namespace dwellfit

namespace dwellfit {
namespace {

TEST(SolveStableRootNear, AgreesWithTheSafeguardedSolverEverywhere) {
  // Frequencies across and beyond the bistable band, levels below, inside and
  // above it, guesses near and far from each root, and both branches
  // (including where the requested branch does not reach a_base).
  int fast_path_used = 0;
  int cases = 0;
  for (double hz = 38.0; hz <= 46.0; hz += 0.25) {
    const auto k = At(hz);
    for (double a_base : {0.002, 0.006, 0.01, 0.02, 0.035, 0.05}) {
      for (Branch branch : {Branch::kLower, Branch::kUpper, Branch::kOnly}) {
        const StableRoot reference = SolveStableRoot(k, a_base, branch, 1e-3);
        for (double factor : {0.3, 0.9, 1.0, 1.1, 3.0}) {
          const double guess = reference.a * factor;
          const StableRoot full = SolveStableRoot(k, a_base, branch, guess);
          const StableRoot near = SolveStableRootNear(k, a_base, branch, guess);
          ++cases;
          ASSERT_EQ(near.status, full.status) << hz << " Hz, a_base " << a_base << ", "
                                              << BranchName(branch) << ", guess " << guess;
          EXPECT_NEAR(near.a, full.a, 1e-13 * full.a)
              << hz << " Hz, a_base " << a_base << ", " << BranchName(branch);
          fast_path_used += near.branch == branch && full.branch != branch;
        }
      }
    }
  }
  EXPECT_GT(cases, 1000);
  // Where G is monotone the fast path answers without the turning points.
  EXPECT_GT(fast_path_used, 0);
}

// The branch certificate over random models, hardening and softening, with
// damping of either sign (c3 < 0 has no certificate), random levels and
// guesses from a tenth to ten times the root: the fast path returns the
// safeguarded solver's root and status every time.
TEST(SolveStableRootNear, AgreesWithTheSafeguardedSolverOnRandomModels) {
  std::mt19937_64 generator(20261122);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(generator)); };
  int cases = 0;
  int certified = 0;
  for (int model = 0; model < 400; ++model) {
    ParameterVector p;
    p[kEtaE] = log_uniform(1.0, 1e3);
    p[kMu1] = (unit(generator) < 0.1 ? -1.0 : 1.0) * log_uniform(1e-3, 10.0);
    p[kMu2] = (unit(generator) < 0.1 ? -1.0 : 1.0) * log_uniform(1e-2, 1e4);
    p[kDelta] = (unit(generator) - 0.5) * 2e6;
    p[kAlpha] = (unit(generator) < 0.2 ? -1.0 : 1.0) * log_uniform(1e6, 1e12);
    p[kNaturalFrequency] = log_uniform(100.0, 2000.0);
    const double omega = p[kNaturalFrequency] * (0.8 + 0.5 * unit(generator));
    const auto k = ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(), omega);
    const double a_base = log_uniform(1e-4, 1.0);
    for (Branch branch : {Branch::kLower, Branch::kUpper}) {
      const StableRoot reference = SolveStableRoot(k, a_base, branch, 1e-3);
      if (reference.status == RootStatus::kFailed) continue;
      for (int g = 0; g < 5; ++g) {
        const double guess = reference.a * log_uniform(0.1, 10.0);
        const StableRoot full = SolveStableRoot(k, a_base, branch, guess);
        const StableRoot near = SolveStableRootNear(k, a_base, branch, guess);
        ++cases;
        ASSERT_EQ(near.status, full.status) << "model " << model << ", " << BranchName(branch);
        EXPECT_NEAR(near.a, full.a, 1e-12 * full.a)
            << "model " << model << ", " << BranchName(branch);
        certified += internal::CertifiedOnBranch(k, near.a, branch);
      }
    }
  }
  EXPECT_GT(cases, 3000);
  EXPECT_GT(certified, cases / 4);
  std::printf("%d cases, %d with a certified root\n", cases, certified);
}

}  // namespace
}  // namespace dwellfit
