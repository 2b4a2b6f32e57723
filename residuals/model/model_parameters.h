// The six model parameters of eq. (3.12) and the layout of the one parameter
// block every dwellfit functor reads.
//
//   index  name    unit / meaning
//   0      eta_e   forcing effectiveness [A/(B s^2)], A the unit of a, B of a_base
//   1      mu1     linear damping [1/s]
//   2      mu2     quadratic (aerodynamic) damping [1/(A s)]: the term is (mu2/Omega) u'|u'|
//   3      delta   nonlinear inertia [1/A^2]
//   4      alpha   cubic stiffness [1/(A^2 s^2)]
//   5      omega   linear natural frequency w [rad/s]
// A member of the family (ModelForm) holds mu3 [1/(A^2 s)] in entry 2 or
// alpha5 [1/(A^4 s^2)] in entry 3 instead.
#ifndef DWELLFIT_RESIDUALS_MODEL_MODEL_PARAMETERS_H_
#define DWELLFIT_RESIDUALS_MODEL_MODEL_PARAMETERS_H_

#include <array>
#include <cmath>
#include <string>

namespace dwellfit {

enum ParameterIndex : int {
  kEtaE = 0,
  kMu1 = 1,
  kMu2 = 2,
  kDelta = 3,
  kAlpha = 4,
  kNaturalFrequency = 5,
  kNumParameters = 6,
  // The family's terms, in the entries of the chapter's terms they replace
  // (ModelForm, model_form.h).
  kMu3 = kMu2,
  kAlpha5 = kDelta,
};

// Values in the order of ParameterIndex; omega in rad/s.
using ParameterVector = std::array<double, kNumParameters>;

inline constexpr std::array<const char*, kNumParameters> kParameterNames = {
    "eta_e", "mu1", "mu2", "delta", "alpha", "omega"};

inline const char* ParameterName(int index) { return kParameterNames[index]; }

// Returns false when `name` is not one of kParameterNames.
inline bool ParameterIndexFromName(const std::string& name, ParameterIndex* index) {
  for (int i = 0; i < kNumParameters; ++i) {
    if (name == kParameterNames[i]) {
      *index = static_cast<ParameterIndex>(i);
      return true;
    }
  }
  return false;
}

inline constexpr double kTwoPi = 6.283185307179586476925286766559;

// Files carry Hz; everything inside the library is rad/s.
inline double HzToRadPerSecond(double hz) { return kTwoPi * hz; }
inline double RadPerSecondToHz(double rad_s) { return rad_s / kTwoPi; }

// The chapter's effective cubic nonlinearity -(1/3)(2 delta Omega_ref^2 - 3 alpha)
// = alpha - (2/3) delta Omega_ref^2 (docs/model.md, "Identifiability").
inline double EffectiveNonlinearity(const ParameterVector& p, double omega_ref_rad_s) {
  return p[kAlpha] - (2.0 / 3.0) * p[kDelta] * omega_ref_rad_s * omega_ref_rad_s;
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_MODEL_PARAMETERS_H_
