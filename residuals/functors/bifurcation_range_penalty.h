// BifurcationRangePenalty: a measured jump must be the model's fold
// (eq. 3.17, section 3.2.4).
//
// Cost (the square of the residual):
//   weight * u^n,   u = (c_model - c_centre) / c_halfwidth,   n even (10 by default)
// c is the jump's control (Omega [rad/s] of a frequency sweep, a_base of an
// amplitude sweep), c_centre and c_halfwidth the measured bracket's, c_model
// the model's fold (fold_point.h). The residual is sqrt(weight) u^(n/2): zero
// at the bracket's centre, small inside (u < 1), growing fast outside.
//
// Where the model has no fold to match (say the damping is too high for a
// jump), u = kNoFoldDistance + s, a large finite penalty whose gradient is
// that of the slack s = max(0, h(a_jump) / h(0)) at the bracket, h(a) =
// (dG/da)/a: h(a_jump) < 0 is the condition for a fold near the measured jump
// amplitude, so lowering s moves the model towards having one.
//
// Parameter block p as in model_parameters.h.
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_BIFURCATION_RANGE_PENALTY_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_BIFURCATION_RANGE_PENALTY_H_

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

class BifurcationRangePenalty {
 public:
  // u for a fold that does not exist: a fold this many half-widths away costs
  // as much as none.
  static constexpr double kNoFoldDistance = 1e3;

  // `control_kind`: which control the jump's bracket is in. `held`: the other
  // control (a_base for a frequency sweep, Omega [rad/s] for an amplitude
  // sweep). `a_jump`: the measured amplitude on the branch that ends.
  // `form`: the response model's (model_form.h).
  BifurcationRangePenalty(ModelForm form, SweepKind control_kind, JumpKind fold_kind, double held,
                          double control_before, double control_after, double a_jump, int exponent,
                          double weight)
      : form_(form),
        control_kind_(control_kind),
        fold_kind_(fold_kind),
        held_(held),
        centre_(0.5 * (control_before + control_after)),
        half_width_(0.5 * std::abs(control_after - control_before)),
        a_jump_(a_jump),
        half_exponent_(exponent / 2),
        sqrt_weight_(std::sqrt(weight)) {}

  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    ParameterVector value;
    for (int i = 0; i < kNumParameters; ++i) value[i] = ScalarPart(p[i]);
    T u;
    const FoldPoint fold = SolveFold(value);
    if (fold.exists) {
      const T c_model = control_kind_ == SweepKind::kFrequency
                            ? LiftFrequencyFold(form_, p, held_, fold)
                            : LiftAmplitudeFold(form_, p, held_, fold);
      u = (c_model - centre_) / half_width_;
    } else {
      u = kNoFoldDistance + FoldSlack(p);
    }
    T power(1.0);
    for (int i = 0; i < half_exponent_; ++i) power *= u;
    residual[0] = sqrt_weight_ * power;
    return true;
  }

  // The model's fold for this bracket, in double.
  FoldPoint SolveFold(const ParameterVector& p) const {
    if (control_kind_ == SweepKind::kFrequency) {
      return SolveFrequencyFold(form_, p.data(), held_, fold_kind_, centre_,
                                std::max(half_width_, 1e-4 * centre_));
    }
    return SolveAmplitudeFold(form_, p.data(), held_, fold_kind_);
  }

  static ceres::CostFunction* Create(ModelForm form, SweepKind control_kind, JumpKind fold_kind,
                                     double held, double control_before, double control_after,
                                     double a_jump, int exponent, double weight) {
    return new ceres::AutoDiffCostFunction<BifurcationRangePenalty, 1, kNumParameters>(
        new BifurcationRangePenalty(form, control_kind, fold_kind, held, control_before,
                                    control_after, a_jump, exponent, weight));
  }

 private:
  template <typename T>
  T FoldSlack(const T* p) const {
    const double omega = control_kind_ == SweepKind::kFrequency ? centre_ : held_;
    const auto k = ResponseCoefficients<T>::FromParameters(form_, p, omega);
    const T a(a_jump_);
    const T slack = k.h(a) / (2.0 * k.c2());
    return slack > 0.0 ? slack : T(0.0);
  }

  const ModelForm form_;
  const SweepKind control_kind_;
  const JumpKind fold_kind_;
  const double held_;
  const double centre_;
  const double half_width_;
  const double a_jump_;
  const int half_exponent_;
  const double sqrt_weight_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_BIFURCATION_RANGE_PENALTY_H_
