// Cross-check of the fixed-point model against the equation of motion itself.
//
// Equation of motion (docs/model.md, 3.12), Omega constant during one dwell:
//   u'' + w^2 u + delta (u u'^2 + u^2 u'') + alpha u^3 + 2 mu1 u' + (mu2/Omega) u'|u'|
//       = 2 eta_e a_base cos(Omega t)
// solved for u'' (the delta term multiplies it):
//   u'' = (2 eta_e a_base cos(Omega t) - w^2 u - delta u u'^2 - alpha u^3 - 2 mu1 u'
//          - (mu2/Omega) u'|u'|) / (1 + delta u^2).
// Integrated with Boost.Odeint's classical Runge-Kutta at a fixed step of
// 1/kStepsPerPeriod period to steady state, from the model's fixed point
// u = a cos(Omega t - gamma) at t = 0 (or from elsewhere, to see a jump). The
// first-harmonic amplitude is the projection of u onto cos and sin of Omega t
// over whole periods (rectangle rule, exact for a periodic signal up to
// aliasing of harmonics above kStepsPerPeriod / 2):
//   c = (2/n) sum u_j cos(Omega t_j),  s = (2/n) sum u_j sin(Omega t_j),  a_1 = hypot(c, s).
// The multiple-scales model is a first-order approximation, so 1% agreement
// with the integrated steady state is the expectation, not exact equality.
// Measured (unchanged at 256 steps per period or 4x longer settling): lower
// root at 41.5 Hz, a_base 0.02: -0.001%; upper root: -0.16%; 38 Hz from
// rest: 0.0001%; the jump up at a_base 0.036: -0.17%.
#include <array>
#include <cmath>

#include "boost/numeric/odeint.hpp"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "dwellfit/residuals/model/stable_root.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

namespace odeint = boost::numeric::odeint;
using State = std::array<double, 2>;  // u, u'

constexpr int kStepsPerPeriod = 64;

// Table 3.1 truth with w = 2 pi 40 rad/s (docs/model.md).
ParameterVector Truth() { return {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)}; }

// Right-hand side of (3.12) as a first-order system.
struct BeamModeEquation {
  ParameterVector p;
  double omega_drive_rad_s;
  double a_base;

  void operator()(const State& x, State& dxdt, double t) const {
    const double u = x[0];
    const double v = x[1];
    const double w = p[kNaturalFrequency];
    const double force = 2.0 * p[kEtaE] * a_base * std::cos(omega_drive_rad_s * t);
    const double restoring = w * w * u + p[kDelta] * u * v * v + p[kAlpha] * u * u * u;
    const double damping = 2.0 * p[kMu1] * v + (p[kMu2] / omega_drive_rad_s) * v * std::abs(v);
    dxdt[0] = v;
    dxdt[1] = (force - restoring - damping) / (1.0 + p[kDelta] * u * u);
  }
};

// The first-harmonic amplitude of u over `measure_periods` whole periods after
// `settle_periods`, starting from `start` at t = 0.
double SteadyFirstHarmonic(const ParameterVector& p, double omega_drive_rad_s, double a_base,
                           State start, int settle_periods, int measure_periods) {
  const BeamModeEquation equation{p, omega_drive_rad_s, a_base};
  const double dt = kTwoPi / omega_drive_rad_s / kStepsPerPeriod;
  odeint::runge_kutta4<State> stepper;
  State x = start;
  odeint::integrate_n_steps(stepper, equation, x, 0.0, dt, settle_periods * kStepsPerPeriod);
  const int samples = measure_periods * kStepsPerPeriod;
  const int first_sample = settle_periods * kStepsPerPeriod;
  double c = 0.0;
  double s = 0.0;
  for (int j = 0; j < samples; ++j) {
    // The phase from the step count, not from an accumulated time.
    const double phase =
        kTwoPi * static_cast<double>((first_sample + j) % kStepsPerPeriod) / kStepsPerPeriod;
    c += x[0] * std::cos(phase);
    s += x[0] * std::sin(phase);
    stepper.do_step(equation, x, (first_sample + j) * dt, dt);
  }
  return 2.0 / samples * std::hypot(c, s);
}

// u and u' at t = 0 on the model's fixed point with amplitude `a`:
// u = a cos(Omega t - gamma), with a_base sin(gamma) = P(a), a_base cos(gamma) = Q(a).
State OnFixedPoint(const ParameterVector& p, double omega_drive_rad_s, double a) {
  const auto k =
      ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(), omega_drive_rad_s);
  const double gamma = std::atan2(k.P(a), k.Q(a));
  return {a * std::cos(gamma), a * omega_drive_rad_s * std::sin(gamma)};
}

TEST(TimeIntegration, BothStableRootsAt41_5HzAreSteadyStatesOfTheEquationOfMotion) {
  const ParameterVector p = Truth();
  const double omega = HzToRadPerSecond(41.5);
  const double a_base = 0.02;  // bistable: between 0.0068 and 0.0354
  for (Branch branch : {Branch::kLower, Branch::kUpper}) {
    const StableRoot root = ModelAmplitude(kFirstOrderForm, p, omega, a_base, branch, 3e-3);
    ASSERT_EQ(root.status, RootStatus::kOnBranch);
    const double a = SteadyFirstHarmonic(p, omega, a_base, OnFixedPoint(p, omega, root.a),
                                         /*settle_periods=*/400, /*measure_periods=*/20);
    EXPECT_NEAR(a / root.a, 1.0, 0.01)
        << BranchName(branch) << ": model " << root.a << ", integrated " << a;
  }
}

TEST(TimeIntegration, SingleValuedResponseIsReachedFromRest) {
  const ParameterVector p = Truth();
  const double omega = HzToRadPerSecond(38.0);
  const double a_base = 0.01;
  ASSERT_FALSE(FindTurningPoints(
                   ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(), omega))
                   .exist);
  const StableRoot root = ModelAmplitude(kFirstOrderForm, p, omega, a_base, Branch::kOnly, 0.0);
  const double a = SteadyFirstHarmonic(p, omega, a_base, State{0.0, 0.0},
                                       /*settle_periods=*/1200, /*measure_periods=*/20);
  EXPECT_NEAR(a / root.a, 1.0, 0.01) << "model " << root.a << ", integrated " << a;
}

// Above the jump-up level the lower branch no longer exists: a response that
// starts where it ended (its turning point) ends on the upper root, which is
// what the dwell simulator does at that step.
TEST(TimeIntegration, ResponseJumpsUpWhereTheLowerBranchHasEnded) {
  const ParameterVector p = Truth();
  const double omega = HzToRadPerSecond(41.5);
  const double a_base = 0.036;  // just above the jump-up level 0.0354
  const TurningPoints tp = FindTurningPoints(
      ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(), omega));
  ASSERT_TRUE(tp.exist);
  const SettledDwell dwell =
      SettleDwell(kFirstOrderForm, p, omega, a_base, Branch::kLower, 0.9 * tp.a_lower_end);
  ASSERT_TRUE(dwell.jumped);
  const double a = SteadyFirstHarmonic(p, omega, a_base, OnFixedPoint(p, omega, tp.a_lower_end),
                                       /*settle_periods=*/800, /*measure_periods=*/20);
  EXPECT_NEAR(a / dwell.amplitude, 1.0, 0.01)
      << "simulator " << dwell.amplitude << ", integrated " << a;
}

}  // namespace
}  // namespace dwellfit
