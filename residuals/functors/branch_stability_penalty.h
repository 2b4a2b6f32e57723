// BranchStabilityPenalty: a dwell measured on a stable branch must lie where
// that branch exists and is stable, never on the unstable middle branch
// (eq. 3.19, section 3.2.4).
//
// Cost (the square of the residual), at the dwell's drive frequency Omega_i:
//   upper branch:  weight * exp(Lambda (a_upper_end - a_i))
//   lower branch:  weight * exp(Lambda (a_i - a_lower_end))
// where a_upper_end (a_lower_end) is the amplitude at which the upper (lower)
// stable branch ends (the turning points of G, stable_root.h), a_i the
// measured amplitude and Lambda [1/amplitude] large: the cost is negligible
// while the point is on its branch's side of the fold and grows
// exponentially past it. Where G has no turning point at Omega_i the response
// is single-valued and the cost is 0. The residual is
// sqrt(weight) exp(Lambda (...) / 2); the turning point is lifted to Jets by
// one Newton step on dG/da = 0.
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_BRANCH_STABILITY_PENALTY_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_BRANCH_STABILITY_PENALTY_H_

#include <cmath>

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

class BranchStabilityPenalty {
 public:
  // `branch` must be kLower or kUpper; `lambda` is Lambda [1/amplitude].
  // `form`: the response model's (model_form.h).
  BranchStabilityPenalty(ModelForm form, double drive_frequency_rad_s, double a_measured,
                         Branch branch, double lambda, double weight)
      : form_(form),
        drive_frequency_rad_s_(drive_frequency_rad_s),
        a_measured_(a_measured),
        upper_(branch == Branch::kUpper),
        lambda_(lambda),
        sqrt_weight_(std::sqrt(weight)) {}

  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    const auto k = ResponseCoefficients<T>::FromParameters(form_, p, drive_frequency_rad_s_);
    const TurningPoints tp = FindTurningPoints(ScalarCoefficients(k));
    if (!tp.exist) {
      residual[0] = T(0.0);
      return true;
    }
    const double a0 = upper_ ? tp.a_upper_end : tp.a_lower_end;
    const T a_fold = a0 - k.dG(a0) / k.d2G(a0);
    const T excess = upper_ ? a_fold - a_measured_ : a_measured_ - a_fold;
    residual[0] = sqrt_weight_ * exp(0.5 * lambda_ * excess);
    return true;
  }

  static ceres::CostFunction* Create(ModelForm form, double drive_frequency_rad_s,
                                     double a_measured, Branch branch, double lambda,
                                     double weight) {
    return new ceres::AutoDiffCostFunction<BranchStabilityPenalty, 1, kNumParameters>(
        new BranchStabilityPenalty(form, drive_frequency_rad_s, a_measured, branch, lambda,
                                   weight));
  }

 private:
  const ModelForm form_;
  const double drive_frequency_rad_s_;
  const double a_measured_;
  const bool upper_;
  const double lambda_;
  const double sqrt_weight_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_BRANCH_STABILITY_PENALTY_H_
