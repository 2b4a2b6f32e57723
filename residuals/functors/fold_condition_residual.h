// FoldConditionResidual: the bifurcation-range constraint (eq. 3.17) in the
// algebraic form of eq. (3.11), for the algebraic stage.
//
// A measured jump ends a branch at (Omega_c, a_base, a_j): Omega_c the
// bracket's centre [rad/s] and a_base the held level (frequency sweep), or
// the held Omega and the bracket's centre level (amplitude sweep); a_j the
// measured amplitude on the branch that ends. The model has its fold there
// when G has a turning point at a_j on the level a_base (docs/model.md,
// "Stability and folds"):
//
//   r_0 = s (G(a_j; Omega_c) - a_base^2) / a_base^2
//   r_1 = s a_j dG/da(a_j; Omega_c) / a_base^2
//
// Both are polynomials in the parameters, defined also where the model has no
// fold (where bifurcation_range_penalty.h has nothing to measure): the
// algebraic stage adds one per enforced jump so that every enforced fold
// exists near its bracket; the vertical stage then places it exactly with the
// penalty. s weighs the jump against the dwells' AlgebraicResidual.
//
// Parameter block p as in model_parameters.h.
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_FOLD_CONDITION_RESIDUAL_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_FOLD_CONDITION_RESIDUAL_H_

#include <cmath>

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

class FoldConditionResidual {
 public:
  // `form`: the response model's (model_form.h).
  FoldConditionResidual(ModelForm form, double drive_frequency_rad_s, double a_base, double a_jump,
                        double weight)
      : form_(form),
        drive_frequency_rad_s_(drive_frequency_rad_s),
        a_base_squared_(a_base * a_base),
        a_jump_(a_jump),
        weight_(weight) {}

  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    const auto k = ResponseCoefficients<T>::FromParameters(form_, p, drive_frequency_rad_s_);
    const double a = a_jump_;
    residual[0] = weight_ * (k.G(a) - a_base_squared_) / a_base_squared_;
    residual[1] = weight_ * a * k.dG(a) / a_base_squared_;
    return std::isfinite(ScalarPart(residual[0])) && std::isfinite(ScalarPart(residual[1]));
  }

  static ceres::CostFunction* Create(ModelForm form, double drive_frequency_rad_s, double a_base,
                                     double a_jump, double weight) {
    return new ceres::AutoDiffCostFunction<FoldConditionResidual, 2, kNumParameters>(
        new FoldConditionResidual(form, drive_frequency_rad_s, a_base, a_jump, weight));
  }

 private:
  const ModelForm form_;
  const double drive_frequency_rad_s_;
  const double a_base_squared_;
  const double a_jump_;
  const double weight_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_FOLD_CONDITION_RESIDUAL_H_
