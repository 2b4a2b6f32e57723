// ModelForm: which reduction of the equation of motion (3.12) the response
// model evaluates (docs/model.md, "Fixed points" and "Terms beyond the
// chapter's").
//
//   kFirstOrder:  the chapter's first-order averaged equation, P and Q of
//                 (3.1)-(3.2) with the coefficients (3.3) (G a sextic);
//   kSecondOrder: harmonic balance on harmonics 1 and 3, to first order in the
//                 third harmonic: Q gains k6 a^5 and P gains k7 a^4 with
//                   g = alpha - 2 delta Omega^2,  D = 9 Omega^2 - w^2,
//                   k6 = 3 g^2 / (32 eta_e D),
//                   k7 = -3 mu2 Omega g / (5 pi eta_e D)
//                 (G of degree ten). Valid away from the superharmonic
//                 resonance 3 Omega = w, where D -> 0.
//
// The form also names the member of the family of single-mode models
// (docs/model.md, "Terms beyond the chapter's"): the parameter block keeps
// six entries, and two of them hold the member's terms:
//
//   entry kMu2 (2):   DampingTerm::kQuadratic  mu2, the chapter's (mu2/Omega) u'|u'|
//                     DampingTerm::kCubic      mu3, 2 mu3 u^2 u' (P gains
//                                              k5 a^3, k5 = Omega mu3 / (4 eta_e))
//   entry kDelta (3): BackboneTerm::kInertia   delta, the chapter's delta u u'^2, delta u^2 u''
//                     BackboneTerm::kQuintic   alpha5, alpha5 u^5 (Q gains
//                                              k6 a^5, k6 = 5 alpha5 / (16 eta_e))
//
// A member with either of the family's terms is evaluated to first order.
//
// Every stage that turns parameters into coefficients takes the form; the
// functors take it in their constructors.
#ifndef DWELLFIT_RESIDUALS_MODEL_MODEL_FORM_H_
#define DWELLFIT_RESIDUALS_MODEL_MODEL_FORM_H_

#include <array>
#include <string>

#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

enum class Averaging { kFirstOrder, kSecondOrder };

enum class DampingTerm { kQuadratic, kCubic };
enum class BackboneTerm { kInertia, kQuintic };

struct ModelForm {
  Averaging averaging = Averaging::kFirstOrder;
  DampingTerm damping = DampingTerm::kQuadratic;
  BackboneTerm backbone = BackboneTerm::kInertia;

  bool second_order() const { return averaging == Averaging::kSecondOrder; }
  // Entry kMu2 holds mu3 (2 mu3 u^2 u') rather than the chapter's mu2.
  bool cubic_damping() const { return damping == DampingTerm::kCubic; }
  // Entry kDelta holds alpha5 (alpha5 u^5) rather than the chapter's delta.
  bool quintic_stiffness() const { return backbone == BackboneTerm::kQuintic; }
  // Whether the member has a term beyond the chapter's eq. (3.12).
  bool family_terms() const { return cubic_damping() || quintic_stiffness(); }
  // Whether entry kDelta is the nonlinear inertia delta (of which the
  // effective nonlinearity alpha - (2/3) delta Omega^2 is formed).
  bool has_inertia() const { return !quintic_stiffness(); }
  bool operator==(const ModelForm& other) const {
    return averaging == other.averaging && damping == other.damping && backbone == other.backbone;
  }
  bool operator!=(const ModelForm& other) const { return !(*this == other); }
};

// The parameters' names for `form`, in ParameterIndex order: entries kMu2
// and kDelta are named after the member's terms ("mu3", "alpha5").
inline std::array<const char*, kNumParameters> ParameterNames(ModelForm form) {
  std::array<const char*, kNumParameters> names = kParameterNames;
  if (form.cubic_damping()) names[kMu2] = "mu3";
  if (form.quintic_stiffness()) names[kDelta] = "alpha5";
  return names;
}
inline const char* ParameterName(ModelForm form, int index) { return ParameterNames(form)[index]; }

// Returns false when `name` is not one of ParameterNames(form).
inline bool ParameterIndexFromName(ModelForm form, const std::string& name, ParameterIndex* index) {
  const auto names = ParameterNames(form);
  for (int i = 0; i < kNumParameters; ++i) {
    if (name == names[i]) {
      *index = static_cast<ParameterIndex>(i);
      return true;
    }
  }
  return false;
}

// The effective cubic nonlinearity of `form`'s member at Omega_ref:
// alpha - (2/3) delta Omega_ref^2 where entry kDelta is the inertia delta,
// alpha itself where it holds alpha5 (docs/model.md, "Identifiability").
inline double EffectiveNonlinearity(ModelForm form, const ParameterVector& p,
                                    double omega_ref_rad_s) {
  return form.has_inertia() ? EffectiveNonlinearity(p, omega_ref_rad_s) : p[kAlpha];
}

// The config keys `model: {damping: ..., backbone: ...}`.
inline const char* DampingTermName(DampingTerm term) {
  return term == DampingTerm::kCubic ? "cubic" : "quadratic";
}
inline const char* BackboneTermName(BackboneTerm term) {
  return term == BackboneTerm::kQuintic ? "quintic" : "inertia";
}

// The chapter's form, spelled out where a caller means it.
inline constexpr ModelForm kFirstOrderForm{Averaging::kFirstOrder};
inline constexpr ModelForm kSecondOrderForm{Averaging::kSecondOrder};

// The names of the config key `model: {averaging: ...}`.
inline const char* AveragingName(Averaging averaging) {
  return averaging == Averaging::kSecondOrder ? "second_order" : "first_order";
}

// Returns false when `name` is neither "first_order" nor "second_order".
inline bool AveragingFromName(const std::string& name, Averaging* averaging) {
  if (name == "first_order") {
    *averaging = Averaging::kFirstOrder;
    return true;
  }
  if (name == "second_order") {
    *averaging = Averaging::kSecondOrder;
    return true;
  }
  return false;
}

// The second order is refused below this drive frequency, a fraction of w:
// its terms grow as 1/D near the superharmonic resonance Omega = w/3, where
// harmonic balance to first order in the third harmonic no longer holds
// (D / w^2 = 1.25 here, against 8 at resonance).
inline constexpr double kSecondOrderMinFrequencyRatio = 0.5;

// The ratio D / w^2 = 9 (Omega / w)^2 - 1 of the second-order terms'
// denominator at `omega_drive_rad_s` (0 at the superharmonic resonance
// Omega = w / 3, 8 at Omega = w).
inline double SuperharmonicDetuning(double omega_drive_rad_s, double natural_frequency_rad_s) {
  const double r = omega_drive_rad_s / natural_frequency_rad_s;
  return 9.0 * r * r - 1.0;
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_MODEL_FORM_H_
