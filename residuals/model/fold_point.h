// FoldPoint: where the model jumps, for a measured jump bracket
// (docs/model.md, "Stability and folds"; section 3.2.4).
//
// A jump-up is where the lower stable branch ends (the local maximum of G at
// a_lower_end); a jump-down is where the upper branch ends (the local minimum
// of G at a_upper_end). Per sweep kind:
//
//   amplitude sweep at fixed Omega: a_base(a) = sqrt(G(a)) is explicit, and
//     the fold level is a_base* = sqrt(G(a*)) with dG/da(a*) = 0.
//   frequency sweep at fixed a_base: (a*, Omega*) solve
//     G(a; Omega) = a_base^2,  dG/da(a; Omega) = 0,
//     found as the root in Omega of phi(Omega) = G(a_turn(Omega); Omega) - a_base^2,
//     a_turn(Omega) the turning point of the requested branch at Omega. By the
//     envelope theorem (dG/da = 0 there) phi'(Omega) = dG/dOmega at fixed a.
//
// Roots are solved in double by safeguarded Newton iterations; the scalar-T
// value (ceres::Jet) is one Newton step from the converged point, whose
// derivative part is the implicit-function-theorem derivative:
//   d a_base*/dp = (dG/dp) / (2 a_base*)          (amplitude sweep, dG/da = 0)
//   d Omega*/dp  = -(dG/dp) / (dG/dOmega)         (frequency sweep, dG/da = 0)
#ifndef DWELLFIT_RESIDUALS_MODEL_FOLD_POINT_H_
#define DWELLFIT_RESIDUALS_MODEL_FOLD_POINT_H_

#include <algorithm>
#include <cmath>
#include <limits>

#include "dwellfit/residuals/model/bracketed_newton.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"
#include "dwellfit/residuals/model/sweep_vocabulary.h"

namespace dwellfit {

// dG/dOmega at fixed a, from dk1/dOmega = k1/Omega, dk2/dOmega = k2/Omega,
// dk3/dOmega = -Omega/eta_e, dk4/dOmega = -delta Omega/(2 eta_e); with the
// second order (model_form.h), g = alpha - 2 delta Omega^2, D = 9 Omega^2 - w^2,
// dg/dOmega = -4 delta Omega, dD/dOmega = 18 Omega:
//   dk6/dOmega = 3 (2 g g' D - g^2 D') / (32 eta_e D^2)
//   dk7/dOmega = -(3 mu2 / (5 pi)) ((g + Omega g') D - Omega g D') / (eta_e D^2).
// A member of the family (form.family_terms(), first order) adds
// dk5/dOmega = k5/Omega and dk6/dOmega = 0.
// `k` are the coefficients at `omega_drive_rad_s` in the same `form`.
template <typename T>
T DerivativeOfGInDriveFrequency(ModelForm form, const T* p, double omega_drive_rad_s,
                                const ResponseCoefficients<T>& k, const T& a) {
  const double omega = omega_drive_rad_s;
  if (form.family_terms()) {
    // A member's own terms: k5 = Omega mu3 / (4 eta_e) grows with Omega as k1
    // and k2 do, k6 = 5 alpha5 / (16 eta_e) does not; dk4/dOmega is the
    // inertia's, 0 where entry kDelta is alpha5.
    const T dp = k.PPerA(a) * a / omega;
    const T delta = form.has_inertia() ? p[kDelta] : T(0.0);
    const T dq = (-omega / p[kEtaE] - delta * omega / (2.0 * p[kEtaE]) * a * a) * a;
    return 2.0 * (k.P(a) * dp + k.Q(a) * dq);
  }
  const T dp = (k.k1 + k.k2 * a) * a / omega;
  const T dq = (-omega / p[kEtaE] - p[kDelta] * omega / (2.0 * p[kEtaE]) * a * a) * a;
  if (!form.second_order()) return 2.0 * (k.P(a) * dp + k.Q(a) * dq);
  const T g = p[kAlpha] - 2.0 * p[kDelta] * omega * omega;
  const T dg = -4.0 * p[kDelta] * omega;
  const T d = 9.0 * omega * omega - p[kNaturalFrequency] * p[kNaturalFrequency];
  const double dd = 18.0 * omega;
  const T eta_d2 = p[kEtaE] * d * d;
  const T dk6 = (3.0 / 32.0) * (2.0 * g * dg * d - g * g * dd) / eta_d2;
  const T dk7 = -(3.0 / (5.0 * kPi)) * p[kMu2] * ((g + omega * dg) * d - omega * g * dd) / eta_d2;
  const T a4 = a * a * a * a;
  return 2.0 * (k.P(a) * (dp + dk7 * a4) + k.Q(a) * (dq + dk6 * a4 * a));
}

inline double TurningAmplitude(const TurningPoints& tp, JumpKind kind) {
  return kind == JumpKind::kJumpUp ? tp.a_lower_end : tp.a_upper_end;
}

struct FoldPoint {
  bool exists = false;
  double a = 0.0;        // response amplitude at the fold
  double control = 0.0;  // a_base (amplitude sweep) or Omega [rad/s] (frequency sweep)
};

// Amplitude sweep at `omega_drive_rad_s`: the a_base where `kind` ends.
inline FoldPoint SolveAmplitudeFold(ModelForm form, const double* p, double omega_drive_rad_s,
                                    JumpKind kind) {
  FoldPoint fold;
  const auto k = ResponseCoefficients<double>::FromParameters(form, p, omega_drive_rad_s);
  const TurningPoints tp = FindTurningPoints(k);
  if (!tp.exist) return fold;
  fold.a = TurningAmplitude(tp, kind);
  fold.control = std::sqrt(k.G(fold.a));
  fold.exists = std::isfinite(fold.control);
  return fold;
}

// Lifts an amplitude-sweep fold to scalar T.
template <typename T>
T LiftAmplitudeFold(ModelForm form, const T* p, double omega_drive_rad_s, const FoldPoint& fold) {
  const auto k = ResponseCoefficients<T>::FromParameters(form, p, omega_drive_rad_s);
  const double a0 = fold.a;
  const T a = a0 - k.dG(a0) / k.d2G(a0);
  return sqrt(k.G(a));
}

// Frequency sweep at `a_base`: the Omega [rad/s] where `kind` ends, searched
// outward from `omega_guess` (the measured bracket's centre) in steps that
// start at `first_step` and double, within a factor 2 of the guess.
inline FoldPoint SolveFrequencyFold(ModelForm form, const double* p, double a_base, JumpKind kind,
                                    double omega_guess, double first_step) {
  FoldPoint fold;
  const double target = a_base * a_base;
  // phi(Omega) and phi'(Omega); false where the branch has no end at Omega.
  auto phi = [&](double omega, double* value, double* slope, double* a) {
    const auto k = ResponseCoefficients<double>::FromParameters(form, p, omega);
    const TurningPoints tp = FindTurningPoints(k);
    if (!tp.exist) return false;
    *a = TurningAmplitude(tp, kind);
    *value = k.G(*a) - target;
    *slope = DerivativeOfGInDriveFrequency(form, p, omega, k, *a);
    return std::isfinite(*value) && std::isfinite(*slope);
  };
  double value0, slope0, a0;
  const bool at_guess = phi(omega_guess, &value0, &slope0, &a0);
  if (at_guess && value0 == 0.0) return {true, a0, omega_guess};
  // Step outward on both sides; a probe where the branch has no end (past
  // the cusp) is bisected back towards the last probe where it has one, since
  // the sign change may lie in between.
  double step = first_step > 0.0 ? first_step : 1e-3 * omega_guess;
  double last_valid[2] = {omega_guess, omega_guess};
  bool side_done[2] = {false, false};
  double lo = 0, hi = 0;
  bool bracketed = false;
  auto differs = [value0](double value) { return (value > 0.0) != (value0 > 0.0); };
  for (int i = 0; i < 64 && step < omega_guess && !bracketed; ++i, step *= 2.0) {
    for (int side = 0; side < 2 && !bracketed; ++side) {
      if (side_done[side]) continue;
      double omega = omega_guess + (side == 0 ? -step : step);
      double value, slope, a;
      if (phi(omega, &value, &slope, &a)) {
        if (!at_guess) return SolveFrequencyFold(form, p, a_base, kind, omega, step / 4.0);
        if (differs(value)) {
          lo = std::min(omega, last_valid[side]);
          hi = std::max(omega, last_valid[side]);
          bracketed = true;
        } else {
          last_valid[side] = omega;
        }
        continue;
      }
      if (!at_guess) continue;
      double invalid = omega;
      for (int j = 0; j < 60 && !bracketed; ++j) {
        const double mid = 0.5 * (last_valid[side] + invalid);
        if (!phi(mid, &value, &slope, &a)) {
          invalid = mid;
        } else if (differs(value)) {
          lo = std::min(mid, last_valid[side]);
          hi = std::max(mid, last_valid[side]);
          bracketed = true;
        } else {
          last_valid[side] = mid;
        }
      }
      side_done[side] = true;
    }
  }
  if (!bracketed) return fold;
  auto phi_for_newton = [&](double omega, double* value, double* slope) {
    double a;
    if (!phi(omega, value, slope, &a)) {
      *value = std::numeric_limits<double>::quiet_NaN();
      *slope = 0.0;
    }
  };
  fold.control = BracketedNewton(phi_for_newton, lo, hi, 0.5 * (lo + hi));
  double value, slope;
  fold.exists = std::isfinite(fold.control) && phi(fold.control, &value, &slope, &fold.a);
  return fold;
}

// Lifts a frequency-sweep fold to scalar T.
template <typename T>
T LiftFrequencyFold(ModelForm form, const T* p, double a_base, const FoldPoint& fold) {
  const auto k = ResponseCoefficients<T>::FromParameters(form, p, fold.control);
  const T a(fold.a);
  return fold.control -
         (k.G(a) - a_base * a_base) / DerivativeOfGInDriveFrequency(form, p, fold.control, k, a);
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_FOLD_POINT_H_
