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
// Every stage that turns parameters into coefficients takes the form; the
// functors take it in their constructors.
#ifndef DWELLFIT_RESIDUALS_MODEL_MODEL_FORM_H_
#define DWELLFIT_RESIDUALS_MODEL_MODEL_FORM_H_

#include <string>

namespace dwellfit {

enum class Averaging { kFirstOrder, kSecondOrder };

struct ModelForm {
  Averaging averaging = Averaging::kFirstOrder;

  bool second_order() const { return averaging == Averaging::kSecondOrder; }
};

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
