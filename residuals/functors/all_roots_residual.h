// AllRootsResidual: one sine-dwell point (Omega_i, a_base_i, a_i) measured
// against the nearest stable root, the chapter's all-roots algorithm
// (section 3.2.2):
//
//   absolute:  r_i = s_i (a_i - a_model)
//   relative:  r_i = s_i (ln(a_i + f) - ln(a_model + f))
//
// where a_model is found by solving the sextic of eq. (3.11),
//   G(a; Omega_i, p) - a_base_i^2 = c6 a^6 + c4 a^4 + c3 a^3 + c2 a^2 - a_base_i^2 = 0,
// for all six roots (Eigen's companion-matrix solver, amplitude_roots.h),
// dropping the negative and complex ones and the unstable middle one
// (dG/da <= 0), and taking the stable root nearest the measured a_i: the
// measurement chooses the branch, as in the chapter (no branch label is used).
// The branch ranges of jumps are enforced through the roots by
// RootTransitionPenalty (root_transition_penalty.h).
//
// Derivatives: the chosen root is lifted to Jets by LiftRoot (stable_root.h).
// Where the nearest stable root changes branch (a fold passes a dwell) the
// residual jumps; the chapter's method has the same discontinuity.
//
// Parameter block p as in model_parameters.h; Omega_i [rad/s].
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_ALL_ROOTS_RESIDUAL_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_ALL_ROOTS_RESIDUAL_H_

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "dwellfit/residuals/model/amplitude_roots.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

class AllRootsResidual {
 public:
  // `form`: the response model's (model_form.h).
  AllRootsResidual(ModelForm form, double drive_frequency_rad_s, double a_base, double a_measured,
                   ErrorMeasure error, double weight, double amplitude_floor = 0.0)
      : form_(form),
        drive_frequency_rad_s_(drive_frequency_rad_s),
        a_base_(a_base),
        a_measured_(a_measured),
        error_(error),
        weight_(weight),
        amplitude_floor_(amplitude_floor) {}

  template <typename T>
  bool operator()(const T* const parameters, T* residual) const {
    const auto k =
        ResponseCoefficients<T>::FromParameters(form_, parameters, drive_frequency_rad_s_);
    StableRoot root;
    if (!NearestStableRoot(ScalarCoefficients(k), a_base_, a_measured_, &root.a)) return false;
    root.status = RootStatus::kOnBranch;
    const T a_model = LiftRoot(k, a_base_, root);
    return AmplitudeError(MeasuredTerm(a_measured_, error_, amplitude_floor_), a_model, error_,
                          weight_, amplitude_floor_, residual);
  }

  static ceres::CostFunction* Create(ModelForm form, double drive_frequency_rad_s, double a_base,
                                     double a_measured, ErrorMeasure error, double weight,
                                     double amplitude_floor = 0.0) {
    return new ceres::AutoDiffCostFunction<AllRootsResidual, 1, kNumParameters>(
        new AllRootsResidual(form, drive_frequency_rad_s, a_base, a_measured, error, weight,
                             amplitude_floor));
  }

 private:
  const ModelForm form_;
  const double drive_frequency_rad_s_;
  const double a_base_;
  const double a_measured_;
  const ErrorMeasure error_;
  const double weight_;
  const double amplitude_floor_;  // f, the data's amplitude unit
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_ALL_ROOTS_RESIDUAL_H_
