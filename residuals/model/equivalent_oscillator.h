// The averaged equations of a member of the family (model_form.h) at one
// amplitude a, as a linear oscillator (docs/model.md, "Fixed points" and
// "Choosing a member"): to first order
//   P(a) = Omega damping a / eta_e,
//   Q(a) = (stiffness - mass Omega^2) a / (8 eta_e),
// with
//   damping   = mu1 + 4 mu2 a / (3 pi)          or  mu1 + mu3 a^2 / 4   [1/s]
//   stiffness = 4 w^2 + 3 alpha a^2 (+ 2.5 alpha5 a^4)                   [1/s^2]
//   mass      = 4 + 2 delta a^2                 (delta = 0 with alpha5)
// The response curves (a quadratic in Omega^2 at fixed a) and the modal
// properties omega(a), zeta(a) are both written in these terms.
#ifndef DWELLFIT_RESIDUALS_MODEL_EQUIVALENT_OSCILLATOR_H_
#define DWELLFIT_RESIDUALS_MODEL_EQUIVALENT_OSCILLATOR_H_

#include "dwellfit/residuals/model/model_form.h"
#include "dwellfit/residuals/model/response_model.h"

namespace dwellfit {

struct EquivalentOscillator {
  double damping = 0.0;    // [1/s]
  double stiffness = 0.0;  // [1/s^2], four times the linear oscillator's
  double mass = 0.0;       // four times the linear oscillator's
};

inline EquivalentOscillator EquivalentOscillatorAt(ModelForm form, const ParameterVector& p,
                                                   double a) {
  EquivalentOscillator o;
  o.damping = form.cubic_damping() ? p[kMu1] + 0.25 * p[kMu3] * a * a
                                   : p[kMu1] + 4.0 * p[kMu2] * a / (3.0 * kPi);
  const double w = p[kNaturalFrequency];
  o.stiffness = 4.0 * w * w + 3.0 * p[kAlpha] * a * a;
  if (form.quintic_stiffness()) o.stiffness += 2.5 * p[kAlpha5] * a * a * a * a;
  const double delta = form.has_inertia() ? p[kDelta] : 0.0;
  o.mass = 4.0 + 2.0 * delta * a * a;
  return o;
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_EQUIVALENT_OSCILLATOR_H_
