// The identified model's amplitude-dependent natural frequency and damping
// ratio, the quantities test engineers compare across methods (docs/model.md,
// "Amplitude-dependent modal properties"). Matching the averaged equations
// near resonance to a linear oscillator of mass m, stiffness k and damping c
// (Q = (k - m Omega^2) a, P = c Omega a, eq. 3.3) at each amplitude a:
//
//   omega(a)^2 = k / m = (4 w^2 + 3 alpha a^2) / (4 + 2 delta a^2)   (the backbone)
//   zeta(a)    = c / (2 sqrt(k m)) = (mu1 + 4 mu2 a / (3 pi)) / ((1 + delta a^2 / 2) omega(a))
//
// The second order (model_form.h) adds k6 a^5 to Q and k7 a^4 to P, which hold
// 1/D(Omega), D = 9 Omega^2 - w^2, g = alpha - 2 delta Omega^2: omega(a) is
// then the root of Q = 0,
//   omega^2 = (4 w^2 + 3 alpha a^2 + (3/4) g^2 a^4 / D) / (4 + 2 delta a^2),
// by fixed-point iteration from the first order's, and zeta(a) takes
// mu1 + 4 mu2 a / (3 pi) - 3 mu2 g a^3 / (5 pi D) at Omega = omega(a).
//
// A member of the family (model_form.h) has delta = 0 where entry kDelta
// holds alpha5, whose k6 a^5 adds 2.5 alpha5 a^4 to the numerator of
// omega(a)^2, and mu1 + mu3 a^2 / 4 for the damping where entry kMu2 holds mu3.
//
// The 95 % bands are linearised: q +/- 1.95996 sqrt(g^T C g), g = dq/dp by
// central differences (relative step 1e-6), C the fit's covariance.
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_MODAL_PROPERTIES_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_MODAL_PROPERTIES_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/parameter_uncertainty.h"

namespace dwellfit {

struct ModalPoint {
  double a = 0.0;                             // response amplitude (data's unit)
  double omega_hz = 0.0, omega_hz_low = 0.0;  // natural frequency [Hz] and its band
  double omega_hz_high = 0.0;
  double zeta = 0.0, zeta_low = 0.0, zeta_high = 0.0;  // damping ratio and its band
};

struct ModalProperties {
  std::vector<ModalPoint> points;  // ascending in a; empty: not computed (`why`)
  bool bands = false;              // false: no covariance, the bands are the values
  std::string why;
};

// omega(a) [rad/s] and zeta(a) at `parameters` (omega in rad/s); NaN where
// the backbone has no real frequency.
// `form`: the response model's.
double ModalFrequency(ModelForm form, const ParameterVector& parameters, double a);
double ModalDampingRatio(ModelForm form, const ParameterVector& parameters, double a);

// `points` amplitudes evenly over [a_min, a_max], with bands from
// `covariance` (physical units, omega in rad/s) when given.
ModalProperties ComputeModalProperties(ModelForm form, const ParameterVector& parameters,
                                       const ParameterMatrix* covariance, double a_min,
                                       double a_max, int points = 25);

// modal_properties.csv: a,omega_hz,omega_hz_low,omega_hz_high,zeta,zeta_low,zeta_high.
std::string ModalPropertiesCsv(const ModalProperties& modal);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_MODAL_PROPERTIES_H_
