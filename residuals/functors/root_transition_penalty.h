// RootTransitionPenalty: the bifurcation range of a measured jump enforced
// through the roots of the sextic (3.11), as the chapter's all-roots
// algorithm does it (section 3.2.3): at a fold the roots of the saddle and the
// node meet and turn complex, so the branch that ends must still have its
// two real roots at the dwell before the jump and have lost them (a complex
// pair) at the dwell after it.
//
// With r1, r2 the two roots of that pair (FoldRootPair, amplitude_roots.h) at a
// control value c, D(c) = (r1 - r2)^2 is real on both sides of the fold:
// positive while the pair is real, -4 Im(r1)^2 once it is complex, and
// continuous through zero at the fold. Two residuals:
//
//   r_1 = sqrt(w) max(0, -D(c_before)) / a_jump^2   the pair must be real before
//   r_2 = sqrt(w) max(0,  D(c_after))  / a_jump^2   and complex after the jump
//
// zero while the transition lies inside the measured bracket, growing
// quadratically in cost as it leaves it (c: Omega [rad/s] of a frequency
// sweep with a_base held, or a_base of an amplitude sweep with Omega held;
// a_jump the measured amplitude before the jump; w the weight).
//
// Derivatives by the implicit function theorem on each root r of
// F(a; p) = G(a; p) - a_base^2 (complex where r is): dr/dp = -F_p(r) / F_a(r),
// F_p = sum_j dG/dk_j dk_j/dp with dG/dk = (2 P a, 2 P a^2, 2 Q a, 2 Q a^3),
// F_a = 2 (P P' + Q Q'); then dD/dp = 2 (r1 - r2)(dr1/dp - dr2/dp). The
// second order (model_form.h) adds dG/dk6 = 2 Q a^5 and dG/dk7 = 2 P a^4, with
// P, Q, P', Q' of response_model.h's higher-order terms. The
// derivative of the coefficients k_j (3.3) in p is taken from ceres::Jet.
// At the fold itself (a double root) F_a = 0 and the derivative does not
// exist; the residuals there are zero on the side that matters.
//
// Parameter block p as in model_parameters.h.
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_ROOT_TRANSITION_PENALTY_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_ROOT_TRANSITION_PENALTY_H_

#include <array>
#include <cmath>
#include <complex>

#include "ceres/jet.h"
#include "ceres/sized_cost_function.h"
#include "dwellfit/residuals/model/amplitude_roots.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/sweep_vocabulary.h"

namespace dwellfit {

// D = (r1 - r2)^2 of the fold pair at one (Omega, a_base), with dD/dp.
struct FoldPairSeparation {
  double d = 0.0;
  std::array<double, kNumParameters> gradient{};
};

namespace internal {

// dr/dp of a (complex) root `a` of G - a_base^2 with the higher-order terms
// (k5, k6, k7): F_a = 2 (P P' + Q Q'), F_p = sum_j dG/dk_j dk_j/dp.
inline bool HigherOrderRootGradient(
    const ResponseCoefficients<ceres::Jet<double, kNumParameters>>& kj,
    const ResponseCoefficients<double>& k, std::complex<double> a,
    std::array<std::complex<double>, kNumParameters>* dr) {
  using C = std::complex<double>;
  const C a2 = a * a;
  const C pa = (k.k1 + (k.k2 + (k.k5 + k.k7 * a) * a) * a) * a;
  const C qa = (k.k3 + (k.k4 + k.k6 * a2) * a2) * a;
  const C dpa = k.k1 + (2.0 * k.k2 + (3.0 * k.k5 + 4.0 * k.k7 * a) * a) * a;
  const C dqa = k.k3 + (3.0 * k.k4 + 5.0 * k.k6 * a2) * a2;
  const C f_a = 2.0 * (pa * dpa + qa * dqa);
  if (!(std::abs(f_a) > 0.0)) return false;
  const C dg_dk[7] = {2.0 * pa * a,      2.0 * pa * a2,     2.0 * qa * a,
                      2.0 * qa * a2 * a, 2.0 * pa * a2 * a, 2.0 * qa * a2 * a2 * a,
                      2.0 * pa * a2 * a2};
  for (int i = 0; i < kNumParameters; ++i) {
    const C f_p = dg_dk[0] * kj.k1.v[i] + dg_dk[1] * kj.k2.v[i] + dg_dk[2] * kj.k3.v[i] +
                  dg_dk[3] * kj.k4.v[i] + dg_dk[4] * kj.k5.v[i] + dg_dk[5] * kj.k6.v[i] +
                  dg_dk[6] * kj.k7.v[i];
    (*dr)[i] = -f_p / f_a;
  }
  return true;
}

}  // namespace internal

// False when the roots have no pair to follow or a root is double.
inline bool SeparationOfFoldPair(ModelForm form, const double* p, double omega_drive_rad_s,
                                 double a_base, bool upper_branch_end, double a_jump,
                                 FoldPairSeparation* out) {
  using Jet = ceres::Jet<double, kNumParameters>;
  std::array<Jet, kNumParameters> jp;
  for (int i = 0; i < kNumParameters; ++i) jp[i] = Jet(p[i], i);
  const auto kj = ResponseCoefficients<Jet>::FromParameters(form, jp.data(), omega_drive_rad_s);
  const ResponseCoefficients<double> k = ScalarCoefficients(kj);
  std::complex<double> r[2];
  if (!FoldRootPair(AmplitudeRoots(k, a_base, a_jump), upper_branch_end, a_jump, &r[0], &r[1])) {
    return false;
  }
  using C = std::complex<double>;
  std::array<C, kNumParameters> dr[2];
  for (int m = 0; m < 2; ++m) {
    if (k.higher_order) {
      if (!internal::HigherOrderRootGradient(kj, k, r[m], &dr[m])) return false;
      continue;
    }
    const C a = r[m];
    const C pa = (k.k1 + k.k2 * a) * a;
    const C qa = (k.k3 + k.k4 * a * a) * a;
    const C f_a = 2.0 * (pa * (k.k1 + 2.0 * k.k2 * a) + qa * (k.k3 + 3.0 * k.k4 * a * a));
    if (!(std::abs(f_a) > 0.0)) return false;
    const C dg_dk[4] = {2.0 * pa * a, 2.0 * pa * a * a, 2.0 * qa * a, 2.0 * qa * a * a * a};
    for (int i = 0; i < kNumParameters; ++i) {
      const C f_p = dg_dk[0] * kj.k1.v[i] + dg_dk[1] * kj.k2.v[i] + dg_dk[2] * kj.k3.v[i] +
                    dg_dk[3] * kj.k4.v[i];
      dr[m][i] = -f_p / f_a;
    }
  }
  const C gap = r[0] - r[1];
  out->d = (gap * gap).real();
  for (int i = 0; i < kNumParameters; ++i) {
    out->gradient[i] = (2.0 * gap * (dr[0][i] - dr[1][i])).real();
  }
  return std::isfinite(out->d);
}

class RootTransitionPenalty : public ceres::SizedCostFunction<2, kNumParameters> {
 public:
  // `control_kind`: which control the jump's bracket is in; `held`: the other
  // control (a_base of a frequency sweep, Omega [rad/s] of an amplitude
  // sweep); `a_jump`: the measured amplitude on the branch that ends; `form`:
  // the response model's (model_form.h).
  RootTransitionPenalty(ModelForm form, SweepKind control_kind, JumpKind fold_kind, double held,
                        double control_before, double control_after, double a_jump, double weight)
      : form_(form),
        control_kind_(control_kind),
        upper_branch_end_(fold_kind == JumpKind::kJumpDown),
        held_(held),
        controls_{control_before, control_after},
        a_jump_(a_jump),
        scale_(std::sqrt(weight) / (a_jump * a_jump)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int side = 0; side < 2; ++side) {
      const bool frequency = control_kind_ == SweepKind::kFrequency;
      const double omega = frequency ? controls_[side] : held_;
      const double a_base = frequency ? held_ : controls_[side];
      FoldPairSeparation s;
      if (!SeparationOfFoldPair(form_, parameters[0], omega, a_base, upper_branch_end_, a_jump_,
                                &s)) {
        return false;
      }
      // Before the jump the pair must be real (D >= 0), after it complex.
      const double sign = side == 0 ? -1.0 : 1.0;
      const double violation = sign * s.d;
      const bool active = violation > 0.0;
      residuals[side] = active ? scale_ * violation : 0.0;
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        for (int i = 0; i < kNumParameters; ++i) {
          jacobians[0][side * kNumParameters + i] = active ? scale_ * sign * s.gradient[i] : 0.0;
        }
      }
    }
    return true;
  }

 private:
  const ModelForm form_;
  const SweepKind control_kind_;
  const bool upper_branch_end_;
  const double held_;
  const double controls_[2];  // before, after the jump
  const double a_jump_;
  const double scale_;  // sqrt(weight) / a_jump^2
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_ROOT_TRANSITION_PENALTY_H_
