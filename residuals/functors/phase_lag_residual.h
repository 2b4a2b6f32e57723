// PhaseLagResidual: the chapter's phase-lag fit (section 3.1, eqs. 3.9-3.10)
// at one dwell (Omega_i, a_base_i, a_i, gamma_i), two residuals:
//
//   r_i1 = s_i (a_base_i sin(gamma_i) - (k1 a_i + k2 a_i^2))    eq. (3.9),  P of (3.1)
//   r_i2 = s_i (a_base_i cos(gamma_i) - (k3 a_i + k4 a_i^3))    eq. (3.10), Q of (3.2)
//
// with k1..k4 the coefficients (3.3) in the physical parameters p
// (model_parameters.h) at Omega_i [rad/s], gamma_i [rad] the measured lag of
// the response behind the base excitation (u ~ a cos(Omega t - gamma) against
// a drive ~ cos(Omega t); docs/model.md, "Phase convention"), and s_i the
// dwell weight divided by a_base_i (each dwell weighs as a relative balance,
// as the algebraic residual does). Linear in 1/eta_e and explicit: no root is
// solved, the derivatives are exact by automatic differentiation.
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_PHASE_LAG_RESIDUAL_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_PHASE_LAG_RESIDUAL_H_

#include <cmath>

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

class PhaseLagResidual {
 public:
  // `form`: the response model's (model_form.h); the second order's P and Q
  // carry k7 a^4 and k6 a^5.
  PhaseLagResidual(ModelForm form, double drive_frequency_rad_s, double a_base, double a_measured,
                   double phase_rad, double weight)
      : form_(form),
        drive_frequency_rad_s_(drive_frequency_rad_s),
        a_measured_(a_measured),
        in_quadrature_(a_base * std::sin(phase_rad)),
        in_phase_(a_base * std::cos(phase_rad)),
        weight_(weight / a_base) {}

  template <typename T>
  bool operator()(const T* const parameters, T* residual) const {
    const auto k =
        ResponseCoefficients<T>::FromParameters(form_, parameters, drive_frequency_rad_s_);
    const double a = a_measured_;
    residual[0] = weight_ * (in_quadrature_ - k.P(a));
    residual[1] = weight_ * (in_phase_ - k.Q(a));
    // Undefined evaluation: a trial step where 1/eta_e overflows.
    return std::isfinite(ScalarPart(residual[0])) && std::isfinite(ScalarPart(residual[1]));
  }

  static ceres::CostFunction* Create(ModelForm form, double drive_frequency_rad_s, double a_base,
                                     double a_measured, double phase_rad, double weight) {
    return new ceres::AutoDiffCostFunction<PhaseLagResidual, 2, kNumParameters>(
        new PhaseLagResidual(form, drive_frequency_rad_s, a_base, a_measured, phase_rad, weight));
  }

 private:
  const ModelForm form_;
  const double drive_frequency_rad_s_;
  const double a_measured_;
  const double in_quadrature_;  // a_base sin(gamma)
  const double in_phase_;       // a_base cos(gamma)
  const double weight_;         // s_i = weight / a_base
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_PHASE_LAG_RESIDUAL_H_
