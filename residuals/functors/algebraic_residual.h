// AlgebraicResidual: the frequency-response equation (3.11) evaluated at one
// measured dwell (Omega_i, a_base_i, a_i):
//
//   r_i = s_i (G(a_i; Omega_i, p) - a_base_i^2) / a_base_i^2
//   G = k4^2 a^6 + (k2^2 + 2 k3 k4) a^4 + 2 k1 k2 a^3 + (k1^2 + k3^2) a^2
// (first order; the second order's G = P^2 + Q^2 with the k6, k7 terms of
// response_model.h, of degree ten)
//
// with the coefficients (3.3). Smooth, cheap and branch-free (it does not
// know which root a point belongs to), so it is the first stage of the
// default fit; the vertical error (VerticalErrorResidual) refines from there.
// Parameter block p as in model_parameters.h; Omega_i [rad/s].
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_ALGEBRAIC_RESIDUAL_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_ALGEBRAIC_RESIDUAL_H_

#include <cmath>

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

class AlgebraicResidual {
 public:
  // `form`: the response model's (model_form.h).
  AlgebraicResidual(ModelForm form, double drive_frequency_rad_s, double a_base, double a_measured,
                    double weight)
      : form_(form),
        drive_frequency_rad_s_(drive_frequency_rad_s),
        a_base_squared_(a_base * a_base),
        a_measured_(a_measured),
        weight_(weight) {}

  template <typename T>
  bool operator()(const T* const parameters, T* residual) const {
    return Evaluate(ParameterTerms<T>(form_, parameters), residual);
  }
  // The same residual from the parameters' terms, which a batch of dwells
  // forms once for all of them.
  template <typename T>
  bool Evaluate(const ParameterTerms<T>& terms, T* residual) const {
    const auto k = ResponseCoefficients<T>::FromTerms(terms, drive_frequency_rad_s_);
    residual[0] = weight_ * (k.G(a_measured_) - a_base_squared_) / a_base_squared_;
    // Undefined evaluation: a trial step where G overflows (eta_e -> 0).
    return std::isfinite(ScalarPart(residual[0]));
  }

  static ceres::CostFunction* Create(ModelForm form, double drive_frequency_rad_s, double a_base,
                                     double a_measured, double weight) {
    return new ceres::AutoDiffCostFunction<AlgebraicResidual, 1, kNumParameters>(
        new AlgebraicResidual(form, drive_frequency_rad_s, a_base, a_measured, weight));
  }

 private:
  const ModelForm form_;
  const double drive_frequency_rad_s_;
  const double a_base_squared_;
  const double a_measured_;
  const double weight_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_ALGEBRAIC_RESIDUAL_H_
