// VerticalErrorResidual: one sine-dwell point (Omega_i, a_base_i, a_i).
//
// Residual (section 3.2.4, the "vertical error" v of Figure 3.17):
//   absolute:  r_i = s_i (a_i - a_model(Omega_i, a_base_i; p))
//   relative:  r_i = s_i (ln(a_i + f) - ln(a_model(Omega_i, a_base_i; p) + f))
// with f >= 0 an amplitude floor (the measurement's noise floor; 0: pure
// relative error): dwells far below f weigh little, dwells far above it are
// measured relatively.
// where a_model is the stable root of the frequency-response equation (3.11)
//   G(a; Omega_i, p) = a_base_i^2
// on the branch the point was measured on (kLower: smallest positive root,
// kUpper: largest, kOnly: the stable root nearest a_i), and s_i a weight
// (1/sigma_i and/or a user weight).
//
// Parameter block p as in model_parameters.h; Omega_i [rad/s].
//
// Root: solved in double on the bracket of its stable branch and lifted to
// Jets (SolveStableRootNear, LiftRoot: stable_root.h). Where the measured
// branch does not reach a_base_i, a_model is the turning point where that
// branch ends (dG/da = 0), so the residual stays continuous as a fold moves
// past a point.
//
// Warm start: on a labelled branch (kLower, kUpper) the Newton iteration
// starts from this dwell's root at its last evaluation (from a_i at the
// first; ForgetRoot restarts cold). A kOnly dwell always starts from a_i.
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_VERTICAL_ERROR_RESIDUAL_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_VERTICAL_ERROR_RESIDUAL_H_

#include <atomic>
#include <cmath>

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/functors/error_measure.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

// The measured side of the error as `error` measures it: a_i, or
// ln(a_i + f) for the relative error (a constant of the dwell, formed once).
inline double MeasuredTerm(double a_measured, ErrorMeasure error, double amplitude_floor) {
  return error == ErrorMeasure::kAbsolute ? a_measured : std::log(a_measured + amplitude_floor);
}

// The weighted error w (measured_term - a_model), or w (measured_term -
// ln(a_model + f)) for the relative error, measured_term = MeasuredTerm(a_i).
// False where undefined: the log of a model amplitude <= 0, or a value that
// is not finite (a root that overflowed at an extreme trial step).
template <typename T>
bool AmplitudeError(double measured_term, const T& a_model, ErrorMeasure error, double weight,
                    double amplitude_floor, T* residual) {
  if (error == ErrorMeasure::kAbsolute) {
    *residual = weight * (measured_term - a_model);
  } else {
    if (!(ScalarPart(a_model) > 0.0)) return false;
    *residual = weight * (measured_term - log(a_model + amplitude_floor));
  }
  return std::isfinite(ScalarPart(*residual));
}

class VerticalErrorResidual {
 public:
  // `form`: the response model's (model_form.h).
  VerticalErrorResidual(ModelForm form, double drive_frequency_rad_s, double a_base,
                        double a_measured, Branch branch, ErrorMeasure error, double weight,
                        double amplitude_floor = 0.0)
      : form_(form),
        drive_frequency_rad_s_(drive_frequency_rad_s),
        a_base_(a_base),
        a_measured_(a_measured),
        branch_(branch),
        error_(error),
        weight_(weight),
        amplitude_floor_(amplitude_floor),
        measured_term_(MeasuredTerm(a_measured, error, amplitude_floor)) {}

  template <typename T>
  bool operator()(const T* const parameters, T* residual) const {
    return Evaluate(ParameterTerms<T>(form_, parameters), residual);
  }
  // The same residual from the parameters' terms, which a batch of dwells
  // forms once for all of them (in this functor's form).
  template <typename T>
  bool Evaluate(const ParameterTerms<T>& terms, T* residual) const {
    const auto k = ResponseCoefficients<T>::FromTerms(terms, drive_frequency_rad_s_);
    // kOnly picks the stable root nearest its guess: that stays a_i.
    const double last_root = last_root_.load(std::memory_order_relaxed);
    const double start = branch_ != Branch::kOnly && last_root > 0.0 ? last_root : a_measured_;
    const StableRoot root = SolveStableRootNear(ScalarCoefficients(k), a_base_, branch_, start);
    // Undefined evaluation: no finite root (non-finite parameters, eta_e = 0).
    if (root.status == RootStatus::kFailed) return false;
    if (root.status == RootStatus::kOnBranch) {
      last_root_.store(root.a, std::memory_order_relaxed);
    }
    const T a_model = LiftRoot(k, a_base_, root);
    return AmplitudeError(measured_term_, a_model, error_, weight_, amplitude_floor_, residual);
  }

  // The next evaluation starts its Newton iteration from a_i, as the first
  // does. The root found may differ from a warm start's in the last bits, so
  // a caller that evaluates a functor again where a fresh one would evaluate
  // (StageProblem::EvaluateAfresh) forgets the root first.
  void ForgetRoot() { last_root_.store(0.0, std::memory_order_relaxed); }

  // The cost function of a functor made with these arguments; `*functor`,
  // when asked, is that functor (owned by the cost function).
  static ceres::CostFunction* Create(ModelForm form, double drive_frequency_rad_s, double a_base,
                                     double a_measured, Branch branch, ErrorMeasure error,
                                     double weight, double amplitude_floor = 0.0,
                                     VerticalErrorResidual** functor = nullptr) {
    auto* made = new VerticalErrorResidual(form, drive_frequency_rad_s, a_base, a_measured, branch,
                                           error, weight, amplitude_floor);
    if (functor != nullptr) *functor = made;
    return new ceres::AutoDiffCostFunction<VerticalErrorResidual, 1, kNumParameters>(made);
  }

 private:
  const ModelForm form_;
  const double drive_frequency_rad_s_;
  const double a_base_;
  const double a_measured_;
  const Branch branch_;
  const ErrorMeasure error_;
  const double weight_;
  const double amplitude_floor_;  // f, the data's amplitude unit
  const double measured_term_;    // MeasuredTerm(a_measured_, error_, amplitude_floor_)
  // The root at the last evaluation (0: none yet): the next Newton start.
  // Atomic so that concurrent evaluations stay well defined.
  mutable std::atomic<double> last_root_{0.0};
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_VERTICAL_ERROR_RESIDUAL_H_
