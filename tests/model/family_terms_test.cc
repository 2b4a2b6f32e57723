// The response model with the terms beyond the chapter's, k5 and k7 (P gains
// k5 a^3 + k7 a^4) and k6 (Q gains k6 a^5): G of degree ten, its derivatives, its roots, its
// turning points and the stable roots on the named branches, against truths that do not use the
// code under test (the product of P's and Q's coefficient vectors, central differences, and sign
// changes of a fine grid refined by bisection).
#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <vector>

#include "ceres/autodiff_cost_function.h"
#include "ceres/gradient_checker.h"
#include "ceres/jet.h"
#include "dwellfit/residuals/model/amplitude_roots.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// A hardening cubic and a softening quintic: Q/a = k3 + k4 a^2 + k6 a^4 = -1 +
// 3 a^2 - a^4 vanishes at a = 0.618 and 1.618, so with light damping G has a
// local maximum, a minimum, a maximum and a minimum on a > 0.
template <typename T = double>
ResponseCoefficients<T> TwoFoldPairs(const T& k5 = T(0.004), const T& k6 = T(-1.0),
                                     const T& k7 = T(0.002)) {
  ResponseCoefficients<T> k{T(0.02), T(0.01), T(-1.0), T(3.0)};
  k.k5 = k5;
  k.k6 = k6;
  k.k7 = k7;
  k.higher_order = true;
  return k;
}

// The roots of f on (lo, hi): sign changes on `n` grid points, refined by
// bisection.
std::vector<double> GridRoots(const std::function<double(double)>& f, double lo, double hi, int n) {
  std::vector<double> roots;
  double x0 = lo, f0 = f(lo);
  for (int i = 1; i <= n; ++i) {
    const double x1 = lo + (hi - lo) * i / n;
    const double f1 = f(x1);
    if ((f0 < 0.0) != (f1 < 0.0)) {
      double a = x0, b = x1, fa = f0;
      for (int j = 0; j < 200 && b - a > 1e-15 * b; ++j) {
        const double m = 0.5 * (a + b);
        const double fm = f(m);
        if ((fm < 0.0) == (fa < 0.0)) {
          a = m;
          fa = fm;
        } else {
          b = m;
        }
      }
      roots.push_back(0.5 * (a + b));
    }
    x0 = x1;
    f0 = f1;
  }
  return roots;
}

TEST(FamilyTerms, GIsTheProductOfPAndQsCoefficientVectors) {
  const ResponseCoefficients<double> k = TwoFoldPairs();
  // P = a (k1 + k2 a + k5 a^2 + k7 a^3), Q = a (k3 + k4 a^2 + k6 a^4), as
  // polynomials.
  const std::vector<double> p = {0.0, k.k1, k.k2, k.k5, k.k7};
  const std::vector<double> q = {0.0, k.k3, 0.0, k.k4, 0.0, k.k6};
  std::vector<double> g(11, 0.0);
  for (size_t i = 0; i < p.size(); ++i)
    for (size_t j = 0; j < p.size(); ++j) g[i + j] += p[i] * p[j];
  for (size_t i = 0; i < q.size(); ++i)
    for (size_t j = 0; j < q.size(); ++j) g[i + j] += q[i] * q[j];
  const double c[11] = {0.0,    0.0,    k.c2(), k.c3(), k.c4(), k.c5(),
                        k.c6(), k.c7(), k.c8(), 0.0,    k.c10()};
  for (int n = 0; n <= 10; ++n) EXPECT_NEAR(c[n], g[n], 1e-15) << "c" << n;
  for (double a : {0.1, 0.7, 1.3, 2.2}) {
    double expanded = 0.0;
    for (int n = 10; n >= 0; --n) expanded = expanded * a + g[n];
    EXPECT_NEAR(k.G(a), expanded, 1e-12 * expanded) << a;
  }
}

TEST(FamilyTerms, DerivativesAgreeWithCentralDifferences) {
  const ResponseCoefficients<double> k = TwoFoldPairs();
  const double e = 1e-5;
  for (double a : {0.15, 0.6, 1.1, 1.9}) {
    EXPECT_NEAR(k.dP(a), (k.P(a + e) - k.P(a - e)) / (2 * e), 1e-7) << a;
    EXPECT_NEAR(k.dQ(a), (k.Q(a + e) - k.Q(a - e)) / (2 * e), 1e-7) << a;
    EXPECT_NEAR(k.dG(a), (k.G(a + e) - k.G(a - e)) / (2 * e), 1e-6 * (1 + std::abs(k.dG(a))));
    EXPECT_NEAR(k.d2G(a), (k.dG(a + e) - k.dG(a - e)) / (2 * e), 1e-6 * (1 + std::abs(k.d2G(a))));
    EXPECT_NEAR(k.h(a), k.dG(a) / a, 1e-12 * (1 + std::abs(k.h(a)))) << a;
    EXPECT_NEAR(k.dh(a), (k.h(a + e) - k.h(a - e)) / (2 * e), 1e-6 * (1 + std::abs(k.dh(a))));
    EXPECT_NEAR(k.d2h(a), (k.dh(a + e) - k.dh(a - e)) / (2 * e), 1e-5 * (1 + std::abs(k.d2h(a))));
  }
}

// The named turning points are the grid's first three sign changes of dG/da:
// the fold pair, then the cap of the upper branch.
void ExpectNamedTurningPoints(const TurningPoints& tp, const std::vector<double>& turning) {
  ASSERT_GE(turning.size(), 3u);
  ASSERT_TRUE(tp.exist);
  EXPECT_NEAR(tp.a_lower_end, turning[0], 1e-12);
  EXPECT_NEAR(tp.a_upper_end, turning[1], 1e-12);
  EXPECT_NEAR(tp.a_upper_limit, turning[2], 1e-12);
}

TEST(FamilyTerms, TurningPointsAreTheFirstThreeSignChangesOfTheSlope) {
  const ResponseCoefficients<double> k = TwoFoldPairs();
  const std::vector<double> turning =
      GridRoots([&k](double a) { return k.dG(a); }, 1e-6, 3.0, 300000);
  ASSERT_EQ(turning.size(), 4u);
  ExpectNamedTurningPoints(FindTurningPoints(k), turning);
}

TEST(FamilyTerms, FindsAllFiveFixedPointsAndTheStableRootsOfTheNamedBranches) {
  const ResponseCoefficients<double> k = TwoFoldPairs();
  auto dg = [&k](double a) { return k.dG(a); };
  const std::vector<double> turning = GridRoots(dg, 1e-6, 3.0, 300000);
  ASSERT_EQ(turning.size(), 4u);
  // A level between the larger local minimum and the smaller local maximum.
  const double g_low = std::max(k.G(turning[1]), k.G(turning[3]));
  const double g_high = std::min(k.G(turning[0]), k.G(turning[2]));
  ASSERT_LT(g_low, g_high);
  const double a_base = std::sqrt(0.5 * (g_low + g_high));
  const std::vector<double> fixed =
      GridRoots([&](double a) { return k.G(a) - a_base * a_base; }, 1e-6, 3.0, 300000);
  ASSERT_EQ(fixed.size(), 5u);

  const std::vector<double> found =
      PositiveRealRoots(k, a_base, AmplitudeRoots(k, a_base, fixed[2]));
  ASSERT_EQ(found.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(found[i], fixed[i], 1e-12 * fixed[i]) << i;

  // The lower branch is the smallest root and the upper branch the root between
  // the second and third turning points (the first fold pair's), from any
  // guess; the largest root, beyond a second fold pair, has no name.
  for (double guess : {0.05, fixed[2], 2.5}) {
    const StableRoot lower = SolveStableRoot(k, a_base, Branch::kLower, guess);
    const StableRoot upper = SolveStableRootNear(k, a_base, Branch::kUpper, guess);
    EXPECT_EQ(lower.status, RootStatus::kOnBranch);
    EXPECT_EQ(upper.status, RootStatus::kOnBranch);
    EXPECT_NEAR(lower.a, fixed.front(), 1e-12 * fixed.front()) << guess;
    EXPECT_NEAR(upper.a, fixed[2], 1e-12 * fixed[2]) << guess;
  }
  // Above the upper branch's top it ends at the third turning point.
  const double over = std::sqrt(1.01 * k.G(turning[2]));
  const StableRoot top = SolveStableRoot(k, over, Branch::kUpper, 1.0);
  EXPECT_EQ(top.status, RootStatus::kBranchEnd);
  EXPECT_NEAR(top.a, turning[2], 1e-12);
  // Above the lower branch's maximum the lower branch ends at its turning point.
  const double above = std::sqrt(1.01 * k.G(turning[0]));
  const StableRoot end = SolveStableRoot(k, above, Branch::kLower, 0.1);
  EXPECT_EQ(end.status, RootStatus::kBranchEnd);
  EXPECT_NEAR(end.a, turning[0], 1e-12);
}

TEST(FamilyTerms, WithoutTheFamilysTermsTheGeneralPathFindsTheSexticsAnswers) {
  // Table 3.1 truth with w = 2 pi 40 rad/s: the sextic's own bracketing
  // (higher_order false) is the independent answer.
  const ParameterVector p = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};
  for (double hz : {41.2, 41.5, 42.3, 43.0}) {
    const auto sextic =
        ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(), kTwoPi * hz);
    ResponseCoefficients<double> general = sextic;
    general.higher_order = true;
    const TurningPoints a = FindTurningPoints(sextic);
    const TurningPoints b = FindTurningPoints(general);
    ASSERT_EQ(a.exist, b.exist) << hz;
    if (!a.exist) continue;
    EXPECT_NEAR(b.a_lower_end, a.a_lower_end, 1e-12 * a.a_lower_end) << hz;
    EXPECT_NEAR(b.a_upper_end, a.a_upper_end, 1e-12 * a.a_upper_end) << hz;
    const double a_base = std::sqrt(0.5 * (sextic.G(a.a_lower_end) + sextic.G(a.a_upper_end)));
    for (Branch branch : {Branch::kLower, Branch::kUpper}) {
      const StableRoot x = SolveStableRoot(sextic, a_base, branch, a.a_upper_end);
      const StableRoot y = SolveStableRoot(general, a_base, branch, a.a_upper_end);
      EXPECT_NEAR(y.a, x.a, 1e-12 * x.a) << hz << " " << BranchName(branch);
    }
  }
}

// The upper-branch root as a function of (k5, k6, k7), through LiftRoot.
struct UpperRootOfFamily {
  explicit UpperRootOfFamily(double a_base) : a_base(a_base) {}
  template <typename T>
  bool operator()(const T* const k567, T* residual) const {
    const ResponseCoefficients<T> k = TwoFoldPairs<T>(k567[0], k567[1], k567[2]);
    const StableRoot root = SolveStableRoot(ScalarCoefficients(k), a_base, Branch::kUpper, 1.0);
    if (root.status == RootStatus::kFailed) return false;
    residual[0] = LiftRoot(k, a_base, root);
    return true;
  }
  double a_base;
};

TEST(FamilyTerms, TheLiftedRootsDerivativeInTheNewTermsPassesTheGradientChecker) {
  const ResponseCoefficients<double> k = TwoFoldPairs();
  const std::vector<double> turning =
      GridRoots([&k](double a) { return k.dG(a); }, 1e-6, 3.0, 300000);
  ASSERT_EQ(turning.size(), 4u);
  // On the upper branch, between its bottom and top.
  const double a_base = std::sqrt(0.5 * (k.G(turning[1]) + k.G(turning[2])));
  ceres::AutoDiffCostFunction<UpperRootOfFamily, 1, 3> cost(new UpperRootOfFamily(a_base));
  ceres::NumericDiffOptions numeric;
  numeric.ridders_relative_initial_step_size = 1e-4;
  const std::vector<const ceres::Manifold*>* euclidean = nullptr;
  ceres::GradientChecker checker(&cost, euclidean, numeric);
  double k567[3] = {0.004, -1.0, 0.002};
  const double* parameters[] = {k567};
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-7, &results)) << results.error_log;
  // The root moves: the derivative is not zero.
  EXPECT_GT(std::abs(results.jacobians[0](0, 1)), 1e-3);
}

// The truths of datasets/virtual-beam (Table 3.1) and datasets/softening-numerical.
const ParameterVector kBeamTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};
const ParameterVector kSofteningTruth = {50.0, 0.5, 100.0, 1e3, -4e8, HzToRadPerSecond(60.0)};

// The second-order form on a softening cubic (kSofteningTruth): k4 < 0 < k6,
// so Q / a turns back at large a and G folds a second time near 0.05-0.07 m,
// a fold of no structure (the correction there outweighs the cubic term it
// corrects).
ResponseCoefficients<double> SofteningSecondOrder(double hz) {
  return ResponseCoefficients<double>::FromParameters(kSecondOrderForm, kSofteningTruth.data(),
                                                      HzToRadPerSecond(hz));
}

TEST(FamilyTerms, ASecondOrderFoldBeyondTheCorrectionsLimitIsNoFold) {
  // Where d(Q/a)/da changes sign: the limit, found on a grid.
  const ResponseCoefficients<double> at60 = SofteningSecondOrder(60.0);
  const std::vector<double> backbone_turn = GridRoots(
      [&at60](double a) { return at60.k4 * a + 2.0 * at60.k6 * a * a * a; }, 1e-6, 0.1, 100000);
  ASSERT_EQ(backbone_turn.size(), 1u);
  EXPECT_NEAR(CorrectionLimit(at60), backbone_turn[0], 1e-12);
  // At 60 Hz, above the softening fold's frequencies, G turns only beyond the
  // limit: no fold, and the branch G rises on ends at the first turning point.
  const std::vector<double> turning =
      GridRoots([&at60](double a) { return at60.dG(a); }, 1e-6, 0.1, 100000);
  ASSERT_EQ(turning.size(), 2u);
  ASSERT_GT(turning[0], backbone_turn[0]);
  const TurningPoints tp = FindTurningPoints(at60);
  EXPECT_FALSE(tp.exist);
  EXPECT_NEAR(tp.a_upper_limit, turning[0], 1e-12);
  // A dwell labelled upper there gets the one root below the limit (the
  // grid's first sign change of G - a_base^2), not a root past the second
  // fold pair, and as a root, not a branch end.
  const double a_base = std::sqrt(at60.G(4e-3));
  const std::vector<double> roots =
      GridRoots([&](double a) { return at60.G(a) - a_base * a_base; }, 1e-6, 0.1, 100000);
  ASSERT_FALSE(roots.empty());
  const StableRoot root = SolveStableRoot(at60, a_base, Branch::kUpper, 0.06);
  EXPECT_EQ(root.status, RootStatus::kOnBranch);
  EXPECT_NEAR(root.a, roots[0], 1e-12);
  // At 59 Hz the softening fold lies within the limit: the fold pair is the
  // grid's first two turning points, the third caps the upper branch.
  const ResponseCoefficients<double> at59 = SofteningSecondOrder(59.0);
  const std::vector<double> turning59 =
      GridRoots([&at59](double a) { return at59.dG(a); }, 1e-6, 0.1, 100000);
  ASSERT_EQ(turning59.size(), 4u);
  ExpectNamedTurningPoints(FindTurningPoints(at59), turning59);
  EXPECT_LT(turning59[1], CorrectionLimit(at59));
  EXPECT_GT(turning59[2], CorrectionLimit(at59));
}

// The family's certificate (internal::CertifiedOnBranchOfFamily) lets the
// warm-started Newton step stand only where it found the branch's root: on
// the second order of both cases, over frequencies, levels, branches and
// guesses, every certified root equals the bracketed solve's, and most
// dwells are certified.
TEST(FamilyTerms, CertifiedNewtonRootsAreTheBracketedSolvesRoots) {
  int certified = 0, compared = 0;
  for (const ParameterVector* p : {&kBeamTruth, &kSofteningTruth}) {
    const double f0 = (*p)[kNaturalFrequency] / kTwoPi;
    for (double hz = 0.9 * f0; hz <= 1.1 * f0; hz += 0.005 * f0) {
      const auto k = ResponseCoefficients<double>::FromParameters(kSecondOrderForm, p->data(),
                                                                  HzToRadPerSecond(hz));
      for (double a_base : {0.002, 0.01, 0.03, 0.05}) {
        for (Branch branch : {Branch::kLower, Branch::kUpper, Branch::kOnly}) {
          const StableRoot exact = SolveStableRoot(k, a_base, branch, 0.0);
          if (exact.status != RootStatus::kOnBranch) continue;
          for (double guess : {0.9 * exact.a, 1.1 * exact.a}) {
            const StableRoot near = SolveStableRootNear(k, a_base, branch, guess);
            ++compared;
            ASSERT_EQ(near.status, RootStatus::kOnBranch);
            EXPECT_NEAR(near.a, exact.a, 1e-12 * exact.a)
                << hz << " Hz, a_base " << a_base << ", " << BranchName(branch);
            certified += internal::CertifiedOnBranchOfFamily(k, near.a, branch) ? 1 : 0;
          }
        }
      }
    }
  }
  EXPECT_GT(compared, 500);
  EXPECT_GT(certified, compared / 2);
  // Where G folds twice the upper branch is never certified (h has four
  // positive roots), the lower one below the first turning point is.
  const ResponseCoefficients<double> k = TwoFoldPairs();
  const TurningPoints tp = FindTurningPoints(k);
  ASSERT_TRUE(tp.exist);
  EXPECT_FALSE(internal::CertifiedOnBranchOfFamily(k, 0.5 * (tp.a_upper_end + tp.a_upper_limit),
                                                   Branch::kUpper));
  EXPECT_TRUE(internal::CertifiedOnBranchOfFamily(k, 0.5 * tp.a_lower_end, Branch::kLower));
  EXPECT_FALSE(internal::CertifiedOnBranchOfFamily(k, 0.5 * tp.a_lower_end, Branch::kOnly));
}

}  // namespace
}  // namespace dwellfit
