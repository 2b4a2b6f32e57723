// The next-dwell ranking against answers computed here without the
// library's residual, root solver or Jacobian: the frequency-response function
// written out by hand, its roots by scanning and bisection, and the Fisher
// information by central differences (docs/next-dwell.md).
#include "dwellfit/estimator/design/next_dwell.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/design/next_dwell_run.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Table 3.1's truth (docs/model.md).
ParameterVector Truth() { return {100.0, 0.2, 300.0, 1e4, 9e8, kTwoPi * 40.0}; }

// G(a) = P^2 + Q^2 of eq. 3.11 with the coefficients of eq. 3.3, by hand.
double HandG(const ParameterVector& p, double omega, double a) {
  const double eta = p[0], mu1 = p[1], mu2 = p[2], delta = p[3], alpha = p[4], w = p[5];
  const double k1 = omega * mu1 / eta, k2 = 4.0 * mu2 * omega / (3.0 * kPi * eta);
  const double k3 = -(omega * omega - w * w) / (2.0 * eta);
  const double k4 = (3.0 * alpha - 2.0 * delta * omega * omega) / (8.0 * eta);
  const double P = k1 * a + k2 * a * a, Q = k3 * a + k4 * a * a * a;
  return P * P + Q * Q;
}

double HandDG(const ParameterVector& p, double omega, double a) {
  const double h = 1e-7 * a;
  return (HandG(p, omega, a + h) - HandG(p, omega, a - h)) / (2.0 * h);
}

// The positive roots of G = level^2 in (0, 0.1], by a fine scan and bisection.
std::vector<double> HandRoots(const ParameterVector& p, double omega, double level) {
  std::vector<double> roots;
  const auto f = [&](double a) { return HandG(p, omega, a) - level * level; };
  const int n = 20000;
  double lo = 1e-9, flo = f(lo);
  for (int i = 1; i <= n; ++i) {
    double hi = 0.1 * i / n, fhi = f(hi);
    if ((flo < 0.0) != (fhi < 0.0)) {
      double a = lo, b = hi;
      for (int k = 0; k < 200; ++k) {
        const double m = 0.5 * (a + b);
        ((f(m) < 0.0) == (f(a) < 0.0) ? a : b) = m;
      }
      roots.push_back(0.5 * (a + b));
    }
    lo = hi;
    flo = fhi;
  }
  return roots;
}

// The model amplitude on a branch: smallest root (lower), largest (upper),
// the one root with dG/da > 0 otherwise.
double HandAmplitude(const ParameterVector& p, double f_hz, double level, Branch branch) {
  const double omega = kTwoPi * f_hz;
  const std::vector<double> roots = HandRoots(p, omega, level);
  if (roots.empty()) return std::nan("");
  if (branch == Branch::kLower) return roots.front();
  if (branch == Branch::kUpper) return roots.back();
  EXPECT_EQ(roots.size(), 1u) << f_hz << " Hz, level " << level;
  return roots.front();
}

// k = 5 time constants of the decay rate mu1 + (2/pi) mu2 a_new.
double Settle(const ParameterVector& p, double a_now, double a_new) {
  return (5.0 + std::log1p(std::abs(a_new - a_now) / a_new)) / (p[1] + 2.0 / kPi * p[2] * a_new);
}

RigLimits Limits() {
  RigLimits limits;
  limits.frequency_min_hz = 38.0;
  limits.frequency_max_hz = 46.0;
  limits.frequency_step_min_hz = 0.5;
  limits.frequency_step_max_hz = 8.0;
  limits.level_min = 0.002;
  limits.level_max = 0.05;
  limits.level_step_min = 0.006;
  limits.level_step_max = 0.05;
  return limits;
}

RigState Upper() { return {41.5, 0.01, Branch::kUpper}; }

// The landing rule on the chapter's case: at level 0.01 the frequency sweep
// (datasets/thesis-numerical/sweeps.csv, simulated dwell by dwell) is
// double-valued at 42 Hz (up: a = 0.0045099, down: a = 0.00031036) and
// single-valued at 43 Hz (a = 0.00020371 both ways).
TEST(LandingPoint, StaysOnItsBranchInTheHysteresisRangeAndJumpsPastItsEnd) {
  const ParameterVector p = Truth();
  Branch branch;
  double a_upper, a_lower, a_past;
  bool jumps;
  ASSERT_TRUE(LandingPoint(kFirstOrderForm, p, Branch::kUpper, 0.0039, 42.0, 0.01, &branch,
                           &a_upper, &jumps));
  EXPECT_EQ(branch, Branch::kUpper);
  EXPECT_FALSE(jumps);
  EXPECT_NEAR(a_upper, 0.0045099, 1e-7);
  ASSERT_TRUE(LandingPoint(kFirstOrderForm, p, Branch::kLower, 0.0005, 42.0, 0.01, &branch,
                           &a_lower, &jumps));
  EXPECT_EQ(branch, Branch::kLower);
  EXPECT_NEAR(a_lower, 0.00031036, 1e-8);
  ASSERT_TRUE(LandingPoint(kFirstOrderForm, p, Branch::kUpper, 0.0039, 43.0, 0.01, &branch, &a_past,
                           &jumps));
  EXPECT_EQ(branch, Branch::kOnly);
  EXPECT_TRUE(jumps);
  EXPECT_NEAR(a_past, 0.00020371, 1e-8);
  // Coming from a single-valued state: the stable root nearer the present amplitude.
  ASSERT_TRUE(LandingPoint(kFirstOrderForm, p, Branch::kOnly, 0.0002, 42.0, 0.01, &branch, &a_lower,
                           &jumps));
  EXPECT_EQ(branch, Branch::kLower);
}

// Only eta_e free: a(eta_e, a_b) depends on eta_e a_b alone (G scales as
// 1/eta_e^2), so da/deta_e = 2 a_b^2 / (eta_e dG/da) and the information of
// one dwell is g^2 / s^2, g = -da/deta_e (absolute error).
TEST(RecommendNextDwell, OnlyEtaFreeMatchesTheAnalyticGainAndRanking) {
  DesignBasis basis;
  basis.estimate = Truth();
  basis.fixed = {false, true, true, true, true, true};
  basis.noise_sigma = 1e-5;
  basis.covariance(0, 0) = 0.04;  // se(eta_e) = 0.2
  basis.residual.error = ErrorMeasure::kAbsolute;
  DesignOptions options;
  const Recommendation rec = RecommendNextDwell(basis, Upper(), Limits(), options);
  ASSERT_GT(rec.ranked.size(), 100u);
  const double a_now = HandAmplitude(basis.estimate, 41.5, 0.01, Branch::kUpper);
  EXPECT_NEAR(rec.present_amplitude, a_now, 1e-9);
  std::vector<double> independent;
  for (const Candidate& c : rec.ranked) {
    const double a = HandAmplitude(basis.estimate, c.frequency_hz, c.level, c.branch);
    ASSERT_NEAR(c.amplitude, a, 1e-9 * a + 1e-15) << c.frequency_hz << " Hz, " << c.level;
    const double omega = kTwoPi * c.frequency_hz;
    const double g = -2.0 * c.level * c.level / (100.0 * HandDG(basis.estimate, omega, a));
    const double gain = std::log1p(g * g * 0.04 / 1e-10);
    EXPECT_NEAR(c.gain, gain, 1e-5 * gain) << c.frequency_hz << " Hz, " << c.level;
    independent.push_back(gain / (Settle(basis.estimate, a_now, a) + 2.0));
  }
  // The library's order is the independent one.
  for (std::size_t i = 1; i < independent.size(); ++i) {
    EXPECT_GE(independent[i - 1], independent[i] * (1.0 - 1e-5)) << "rank " << i;
  }
}

// Five parameters free, the relative error: the Fisher information of a
// small grid of dwells by central differences of ln a, inverted here, and
// each candidate's D-optimal gain log det(1 + G I^-1 G^T / s^2) from the same
// differences (G one row g for a single dwell, three for a segment of three):
// the gains, test times and ranking agree.
TEST(RecommendNextDwell, FiniteDifferenceFisherInformationGivesTheSameRanking) {
  const ParameterVector p = Truth();
  const double s = 0.01;
  const auto row = [&](double f_hz, double level, Branch branch) {
    Eigen::Matrix<double, 5, 1> g;
    for (int j = 0; j < 5; ++j) {
      ParameterVector plus = p, minus = p;
      const double h = 1e-5 * p[j];
      plus[j] += h;
      minus[j] -= h;
      g(j) = -(std::log(HandAmplitude(plus, f_hz, level, branch)) -
               std::log(HandAmplitude(minus, f_hz, level, branch))) /
             (2.0 * h);
    }
    return g;
  };
  // The dwells so far: a coarse frequency sweep up at 0.01 and a level sweep at 41.5 Hz.
  Eigen::Matrix<double, 5, 5> information = Eigen::Matrix<double, 5, 5>::Zero();
  for (double f : {38.0, 39.0, 40.0, 40.5, 41.0, 41.5, 42.0}) {
    const auto g = row(f, 0.01, f < 40.3 ? Branch::kOnly : Branch::kUpper);
    information += g * g.transpose() / (s * s);
  }
  for (double f : {43.0, 44.0, 46.0}) {
    const auto g = row(f, 0.01, Branch::kOnly);
    information += g * g.transpose() / (s * s);
  }
  for (double level : {0.005, 0.02, 0.03, 0.045}) {
    const auto g = row(41.5, level, level < 0.04 ? Branch::kLower : Branch::kUpper);
    information += g * g.transpose() / (s * s);
  }
  DesignBasis basis;
  basis.estimate = p;
  basis.fixed = {false, false, false, false, false, true};
  basis.noise_sigma = s;
  basis.residual.error = ErrorMeasure::kRelative;
  const Eigen::Matrix<double, 5, 5> covariance = information.inverse();
  basis.covariance.topLeftCorner<5, 5>() = covariance;
  RigLimits limits = Limits();
  limits.frequency_step_min_hz = 1.0;
  limits.level_step_min = 0.012;
  DesignOptions options;
  options.segment_dwells = 3;
  const Recommendation rec = RecommendNextDwell(basis, Upper(), limits, options);
  ASSERT_GT(rec.ranked.size(), 20u);
  std::vector<double> independent;
  int segments = 0;
  for (const Candidate& c : rec.ranked) {
    // Walk the candidate's dwells by the landing rule, written out here: with
    // three roots the branch it comes from (from `only`, the root nearer the
    // last amplitude), with one root `only`.
    Branch from = Branch::kUpper;
    double a_prev = HandAmplitude(p, 41.5, 0.01, Branch::kUpper), seconds = 0.0;
    Eigen::MatrixXd rows(c.dwells, 5);
    for (int k = 0; k < c.dwells; ++k) {
      const double f = c.frequency_hz + k * c.frequency_step_hz;
      const double level = c.level + k * c.level_step;
      const std::vector<double> roots = HandRoots(p, kTwoPi * f, level);
      Branch on = Branch::kOnly;
      if (roots.size() == 3 && from != Branch::kOnly) on = from;
      if (roots.size() == 3 && from == Branch::kOnly) {
        on = std::abs(roots.front() - a_prev) <= std::abs(roots.back() - a_prev) ? Branch::kLower
                                                                                 : Branch::kUpper;
      }
      const double a = HandAmplitude(p, f, level, on);
      rows.row(k) = row(f, level, on).transpose();
      seconds += Settle(p, a_prev, a) + 2.0;
      from = on;
      a_prev = a;
    }
    segments += c.dwells == 3;
    const Eigen::MatrixXd gcg = rows * covariance * rows.transpose() / (s * s);
    const double gain =
        std::log((Eigen::MatrixXd::Identity(c.dwells, c.dwells) + gcg).determinant());
    EXPECT_NEAR(c.gain, gain, 1e-3 * gain + 1e-9)
        << c.frequency_hz << " Hz, " << c.level << ", " << c.dwells << " dwells";
    EXPECT_NEAR(c.settle_seconds + c.record_seconds, seconds, 1e-6 * seconds);
    independent.push_back(gain / seconds);
  }
  EXPECT_EQ(segments, 3);  // 3 x +/-1 Hz and 3 x +0.012; the others leave the limits
  for (std::size_t i = 1; i < independent.size(); ++i) {
    EXPECT_GE(independent[i - 1], independent[i] * (1.0 - 1e-3)) << "rank " << i;
  }
}

// The truth, w fixed, 1 % relative noise and a diagonal covariance.
DesignBasis DiagonalBasis() {
  DesignBasis basis;
  basis.estimate = Truth();
  basis.fixed = {false, false, false, false, false, true};
  basis.noise_sigma = 0.01;
  basis.residual.error = ErrorMeasure::kRelative;
  basis.omega_ref_rad_s = kTwoPi * 41.5;
  const Eigen::Matrix<double, 5, 1> scale(1.0, 0.1, 100.0, 3e3, 1e8);
  basis.covariance.topLeftCorner<5, 5>() = (scale.asDiagonal() * 0.01).toDenseMatrix();
  return basis;
}

// A quantity's gain is the Sherman-Morrison drop of its variance: the same as
// the variance from the information with the dwell added, inverted.
TEST(RecommendNextDwell, QuantityGainIsTheVarianceDropOfTheUpdatedInformation) {
  DesignBasis basis = DiagonalBasis();
  DesignOptions options;
  options.target.kind = TargetKind::kEffectiveNonlinearity;
  const Recommendation rec = RecommendNextDwell(basis, Upper(), Limits(), options);
  ASSERT_FALSE(rec.ranked.empty());
  const Candidate& best = rec.ranked.front();
  ParameterGradient g;
  ASSERT_TRUE(
      ResidualGradient(basis, best.frequency_hz, best.level, best.branch, best.amplitude, &g));
  const Eigen::Matrix<double, 5, 5> c0 = basis.covariance.topLeftCorner<5, 5>();
  const Eigen::Matrix<double, 5, 5> after =
      (c0.inverse() + g.head<5>() * g.head<5>().transpose() / 1e-4).inverse();
  Eigen::Matrix<double, 5, 1> c = Eigen::Matrix<double, 5, 1>::Zero();
  c(3) = -(2.0 / 3.0) * basis.omega_ref_rad_s * basis.omega_ref_rad_s;
  c(4) = 1.0;
  EXPECT_NEAR(best.gain, c.dot(c0 * c) - c.dot(after * c), 1e-6 * c.dot(c0 * c));
  EXPECT_NEAR(rec.quantity, 9e8 - (2.0 / 3.0) * 1e4 * std::pow(kTwoPi * 41.5, 2), 1.0);
}

// With the measured level's noise (level_relative_sigma kappa) a single
// dwell's D-optimal gain is log(1 + g^T C g / (s^2 + kappa^2 h^2)), h the
// residual's slope in ln a_b: here h from central differences of the
// residual in the level itself (not the eta_e identity the code uses). The
// level's noise lowers every gain, most where the amplitude is steepest in
// the level.
TEST(RecommendNextDwell, TheLevelsNoiseEntersEachCandidatesNoise) {
  DesignBasis basis = DiagonalBasis();
  const Recommendation exact = RecommendNextDwell(basis, Upper(), Limits(), DesignOptions());
  basis.level_relative_sigma = 0.02;
  const Recommendation noisy = RecommendNextDwell(basis, Upper(), Limits(), DesignOptions());
  ASSERT_EQ(noisy.ranked.size(), exact.ranked.size());
  int checked = 0;
  double largest_drop = 0.0;
  for (const Candidate& c : noisy.ranked) {
    if (c.dwells != 1) continue;
    const auto residual = [&](double level) {
      const std::unique_ptr<ceres::CostFunction> cost(VerticalErrorResidual::Create(
          kFirstOrderForm, kTwoPi * c.frequency_hz, level, c.amplitude, c.branch,
          basis.residual.error, 1.0, basis.residual.amplitude_floor));
      const double* parameters[] = {basis.estimate.data()};
      double r = 0.0;
      EXPECT_TRUE(cost->Evaluate(parameters, &r, nullptr));
      return r;
    };
    const double e = 1e-6;
    const double h = (residual(c.level * (1 + e)) - residual(c.level * (1 - e))) / (2 * e);
    ParameterGradient g;
    ASSERT_TRUE(ResidualGradient(basis, c.frequency_hz, c.level, c.branch, c.amplitude, &g));
    const double variance = 1e-4 + 0.02 * 0.02 * h * h;
    EXPECT_NEAR(c.gain, std::log1p(g.dot(basis.covariance * g) / variance),
                1e-5 * std::max(c.gain, 1e-3))
        << c.frequency_hz << " Hz, level " << c.level;
    for (const Candidate& e0 : exact.ranked) {
      if (e0.dwells == 1 && e0.frequency_hz == c.frequency_hz && e0.level == c.level) {
        EXPECT_LE(c.gain, e0.gain * (1 + 1e-12));
        largest_drop = std::max(largest_drop, 1.0 - c.gain / e0.gain);
      }
    }
    ++checked;
  }
  EXPECT_GT(checked, 10);
  EXPECT_GT(largest_drop, 0.1);
}

// The backbone omega(a) = sqrt((4 w^2 + 3 alpha a^2) / (4 + 2 delta a^2))
// (docs/model.md) and the jump-down frequency of a frequency sweep at level
// 0.01, whose gradient follows from the implicit function theorem on the
// fold: G(a*; Omega*) = a_b^2 with dG/da = 0 there, so dOmega*/dp =
// -(dG/dp) / (dG/dOmega) at fixed a*. Both from the hand-written G.
TEST(QuantityGradient, BackboneAndJumpFrequencyMatchTheirFormulas) {
  DesignBasis basis;
  basis.estimate = Truth();
  basis.fixed = {false, false, false, false, false, true};
  const auto backbone_hz = [](const ParameterVector& p, double a) {
    return std::sqrt((4.0 * p[5] * p[5] + 3.0 * p[4] * a * a) / (4.0 + 2.0 * p[3] * a * a)) /
           kTwoPi;
  };
  DesignTarget target;
  std::string error;
  ASSERT_TRUE(ParseDesignTarget("omega_at=0.004", &target, &error));
  double value;
  ParameterGradient c;
  ASSERT_TRUE(QuantityGradient(basis, target, &value, &c));
  EXPECT_NEAR(value, backbone_hz(basis.estimate, 0.004), 1e-9);
  for (int j = 0; j < 5; ++j) {
    ParameterVector plus = basis.estimate, minus = basis.estimate;
    const double h = 1e-4 * std::max(std::abs(plus[j]), 1.0);
    plus[j] += h;
    minus[j] -= h;
    const double expected = (backbone_hz(plus, 0.004) - backbone_hz(minus, 0.004)) / (2.0 * h);
    EXPECT_NEAR(c(j), expected, 1e-5 * std::abs(expected) + 1e-15) << j;
  }
  // The jump-down at level 0.01: the bundled up sweep drops between 42.2 and 42.3 Hz.
  ASSERT_TRUE(ParseDesignTarget("jump_down_hz=0.01", &target, &error));
  ASSERT_TRUE(QuantityGradient(basis, target, &value, &c));
  EXPECT_GT(value, 42.2);
  EXPECT_LT(value, 42.3);
  // a*: the local minimum of G at Omega*, by golden-section search.
  const ParameterVector& p = basis.estimate;
  const double omega = kTwoPi * value;
  double lo = 0.004, hi = 0.006;  // around the measured 0.0047 before the jump
  for (int k = 0; k < 200; ++k) {
    const double m1 = hi - 0.618 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    if (HandG(p, omega, m1) < HandG(p, omega, m2)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  const double a_star = 0.5 * (lo + hi);
  EXPECT_NEAR(HandG(p, omega, a_star), 1e-4, 1e-8);  // on the level
  const double dw = 1e-6 * omega;
  const double dg_domega = (HandG(p, omega + dw, a_star) - HandG(p, omega - dw, a_star)) / (2 * dw);
  for (int j = 0; j < 5; ++j) {
    ParameterVector plus = p, minus = p;
    const double h = 1e-6 * p[j];
    plus[j] += h;
    minus[j] -= h;
    const double dg_dp = (HandG(plus, omega, a_star) - HandG(minus, omega, a_star)) / (2.0 * h);
    const double expected = -dg_dp / dg_domega / kTwoPi;  // Hz per unit of p_j
    EXPECT_NEAR(c(j), expected, 1e-3 * std::abs(expected)) << j;
  }
}

TEST(DesignTarget, NamesRoundTripAndBadNamesAreRefused) {
  for (const char* name :
       {"d_optimal", "mu2", "alpha_e", "omega_at=0.003", "jump_down_hz=0.01", "jump_up_hz=0.02"}) {
    DesignTarget target;
    std::string error;
    ASSERT_TRUE(ParseDesignTarget(name, &target, &error)) << name << ": " << error;
    EXPECT_EQ(target.Name(), name);
  }
  DesignTarget target;
  std::string error;
  EXPECT_FALSE(ParseDesignTarget("omega_at=-1", &target, &error));
  EXPECT_FALSE(ParseDesignTarget("zeta", &target, &error));
  EXPECT_NE(error.find("d_optimal"), std::string::npos);
}

TEST(NextDwellRun, StateAndLimitsAreParsedAndBadOnesNamed) {
  const RigState state = ParseRigState("f_hz=41.5,level=0.01,branch=lower", "--state");
  EXPECT_EQ(state.frequency_hz, 41.5);
  EXPECT_EQ(state.branch, Branch::kLower);
  EXPECT_THROW(ParseRigState("f_hz=41.5", "--state"), InputError);
  EXPECT_THROW(ParseRigState("f_hz=41.5,level=0.01,branch=middle", "--state"), InputError);
  EXPECT_THROW(ParseRigState("f_hz=x,level=0.01", "--state"), InputError);
  const RigLimits limits = OverrideLimits(Limits(), "f_step_max_hz=1,level_max=0.04", "--limits");
  EXPECT_EQ(limits.frequency_step_max_hz, 1.0);
  EXPECT_EQ(limits.level_max, 0.04);
  try {
    OverrideLimits(Limits(), "f_stepmax_hz=1", "--limits");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("f_stepmax_hz"), std::string::npos);
  }
  EXPECT_THROW(OverrideLimits(Limits(), "level_min=0.06", "--limits"), InputError);
}

// The ranking's decay rate and intervals are the chapter's terms': a member
// of the family (model_form.h) is refused before any fit, naming the key.
TEST(NextDwellRun, AFamilyMemberIsRefusedNamingTheModelKey) {
  IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml");
  config.identification.solve.residual.form.backbone = BackboneTerm::kQuintic;
  std::ostringstream out;
  try {
    ComputeNextDwell(config, NextDwellRequest{}, out);
    FAIL() << "a member's config was taken";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "model");
    EXPECT_NE(std::string(error.what()).find("chapter's terms"), std::string::npos);
  }
  EXPECT_TRUE(out.str().empty());
}

}  // namespace
}  // namespace dwellfit
