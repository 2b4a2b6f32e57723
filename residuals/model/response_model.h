// The single-mode response model of the chapter, templated on the scalar so that
// ceres::Jet values flow through (docs/model.md, "Fixed points").
//
// Fixed points (3.1)-(3.2), with u ~ a cos(Omega t - gamma):
//   P(a) = k1 a + k2 a^2 = a_base sin(gamma)
//   Q(a) = k3 a + k4 a^3 = a_base cos(gamma)
// coefficients (3.3), Omega the drive frequency [rad/s]:
//   k1 = Omega mu1 / eta_e
//   k2 = 4 mu2 Omega / (3 pi eta_e)
//   k3 = -(Omega^2 - w^2) / (2 eta_e)
//   k4 = (3 alpha - 2 delta Omega^2) / (8 eta_e)
// frequency-response function (3.11):
//   G(a) = P(a)^2 + Q(a)^2,  and a fixed point satisfies G(a) = a_base^2.
// Stability: a fixed point is stable iff dG/da > 0; folds (jumps) have dG/da = 0.
// Models beyond the chapter's add k5 a^3 and k7 a^4 to P and k6 a^5 to Q
// (ResponseCoefficients::higher_order; docs/model.md, "Terms beyond the chapter's").
// A member of the family (ModelForm) sets k5 = Omega mu3 / (4 eta_e) (cubic
// damping 2 mu3 u^2 u') and k6 = 5 alpha5 / (16 eta_e) (quintic stiffness
// alpha5 u^5). The second-order form (ModelForm, model_form.h) sets, with
//   g = alpha - 2 delta Omega^2,  D = 9 Omega^2 - w^2:
//   k6 = 3 g^2 / (32 eta_e D),   k7 = -3 mu2 Omega g / (5 pi eta_e D),   k5 = 0.
#ifndef DWELLFIT_RESIDUALS_MODEL_RESPONSE_MODEL_H_
#define DWELLFIT_RESIDUALS_MODEL_RESPONSE_MODEL_H_

#include <array>

#include "dwellfit/residuals/model/model_form.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

inline constexpr double kPi = 3.14159265358979323846264338327950;

// The parts of the coefficients (3.3) that depend on the parameters alone.
// A batch of dwells evaluated at one point forms them once; each dwell then
// combines them with its drive frequency (ResponseCoefficients::FromTerms) in
// the operations, and the order, of FromParameters, so the coefficients are
// the same numbers either way.
template <typename T>
struct ParameterTerms {
  // `form` chooses the terms FromTerms adds; `p` is the parameter block
  // (ParameterIndex layout).
  // A member's own terms (form.family_terms()) take entries kMu2 and kDelta
  // in place of mu2 and delta, which are then 0.
  ParameterTerms(ModelForm form, const T* p)
      : second_order(form.second_order()),
        family(form.family_terms()),
        eta_e(p[kEtaE]),
        two_eta_e(2.0 * p[kEtaE]),
        eight_eta_e(8.0 * p[kEtaE]),
        mu1(p[kMu1]),
        scaled_mu2(form.cubic_damping() ? T(0.0) : T((4.0 / (3.0 * kPi)) * p[kMu2])),
        w_squared(p[kNaturalFrequency] * p[kNaturalFrequency]),
        three_alpha(3.0 * p[kAlpha]),
        two_delta(form.quintic_stiffness() ? T(0.0) : T(2.0 * p[kDelta])) {
    if (second_order) alpha = p[kAlpha];
    if (form.cubic_damping()) quarter_mu3 = 0.25 * p[kMu3];
    if (form.quintic_stiffness()) scaled_alpha5 = (5.0 / 16.0) * p[kAlpha5];
  }

  bool second_order;
  bool family;  // k5, k6 from the member's own terms
  T eta_e, two_eta_e, eight_eta_e;
  T mu1;
  T scaled_mu2;  // 4 mu2 / (3 pi)
  T w_squared;   // w^2 [rad^2/s^2]
  T three_alpha, two_delta;
  T alpha = T(0.0);          // read by the second order only
  T quarter_mu3 = T(0.0);    // mu3 / 4 [1/(A^2 s)]
  T scaled_alpha5 = T(0.0);  // 5 alpha5 / 16 [1/(A^4 s^2)]
};

template <typename T>
struct ResponseCoefficients {
  T k1, k2, k3, k4;
  // Terms beyond eq. (3.3) (docs/model.md, "Terms beyond the chapter's"),
  // read only where `higher_order` is set, so that the chapter's member
  // evaluates exactly the expressions above:
  //   P(a) = (k1 + k2 a + k5 a^2 + k7 a^3) a,   Q(a) = (k3 + k4 a^2 + k6 a^4) a,
  // and G = P^2 + Q^2 is of degree ten.
  T k5 = T(0.0), k6 = T(0.0), k7 = T(0.0);
  bool higher_order = false;
  // Whether k5..k7 are a correction to the first-order terms (the second-order
  // form) rather than a model's own terms: a correction holds only where it is
  // small (CorrectionLimit, stable_root.h).
  bool correction = false;

  // `p` is the parameter block (ParameterIndex layout); `omega_drive` in rad/s.
  template <typename D>
  static ResponseCoefficients FromParameters(ModelForm form, const T* p, const D& omega_drive) {
    return FromTerms(ParameterTerms<T>(form, p), omega_drive);
  }
  // The coefficients (3.3), at the top of this file, from the parameters'
  // terms.
  template <typename D>
  static ResponseCoefficients FromTerms(const ParameterTerms<T>& t, const D& omega_drive) {
    ResponseCoefficients k;
    k.k1 = omega_drive * t.mu1 / t.eta_e;
    k.k2 = t.scaled_mu2 * omega_drive / t.eta_e;
    k.k3 = -(omega_drive * omega_drive - t.w_squared) / t.two_eta_e;
    k.k4 = (t.three_alpha - t.two_delta * omega_drive * omega_drive) / t.eight_eta_e;
    if (t.second_order) AddSecondOrderTerms(t, omega_drive, &k);
    if (t.family) {
      // k5 = Omega mu3 / (4 eta_e), k6 = 5 alpha5 / (16 eta_e) (docs/model.md,
      // "Terms beyond the chapter's").
      k.k5 = omega_drive * t.quarter_mu3 / t.eta_e;
      k.k6 = t.scaled_alpha5 / t.eta_e;
      k.higher_order = true;
    }
    return k;
  }
  // k6 = 3 g^2 / (32 eta_e D), k7 = -3 mu2 Omega g / (5 pi eta_e D), with
  // g = alpha - 2 delta Omega^2, D = 9 Omega^2 - w^2 (harmonic balance on
  // harmonics 1 and 3; -3 mu2 / (5 pi) = -(9/20) (4 mu2 / (3 pi))).
  template <typename D>
  static void AddSecondOrderTerms(const ParameterTerms<T>& t, const D& omega_drive,
                                  ResponseCoefficients* k) {
    const D omega_squared = omega_drive * omega_drive;
    const T g = t.alpha - t.two_delta * omega_squared;
    const T eta_d = t.eta_e * (9.0 * omega_squared - t.w_squared);
    k->k6 = (3.0 / 32.0) * g * g / eta_d;
    k->k7 = -0.45 * t.scaled_mu2 * omega_drive * g / eta_d;
    k->higher_order = true;
    k->correction = true;
  }

  // The amplitude `a` is a T, or a double where it is a constant (a root
  // found in double and lifted to Jets): the same values, with no
  // derivative part carried for it.
  // P(a) / a and Q(a) / a: the polynomials P and Q share with h.
  template <typename A>
  T PPerA(const A& a) const {
    if (higher_order) return k1 + (k2 + (k5 + k7 * a) * a) * a;
    return k1 + k2 * a;
  }
  template <typename A>
  T QPerA(const A& a) const {
    if (higher_order) return k3 + (k4 + k6 * a * a) * a * a;
    return k3 + k4 * a * a;
  }
  template <typename A>
  T P(const A& a) const {
    return PPerA(a) * a;
  }
  template <typename A>
  T Q(const A& a) const {
    return QPerA(a) * a;
  }
  template <typename A>
  T dP(const A& a) const {
    if (higher_order) return k1 + (2.0 * k2 + (3.0 * k5 + 4.0 * k7 * a) * a) * a;
    return k1 + 2.0 * k2 * a;
  }
  template <typename A>
  T dQ(const A& a) const {
    if (higher_order) return k3 + (3.0 * k4 + 5.0 * k6 * a * a) * a * a;
    return k3 + 3.0 * k4 * a * a;
  }

  // G(a) of (3.11), evaluated as P^2 + Q^2 (better conditioned than the
  // expanded sextic).
  template <typename A>
  T G(const A& a) const {
    const T p = P(a);
    const T q = Q(a);
    return p * p + q * q;
  }
  // dG/da = 2 (P P' + Q Q'); its sign is the stability of a fixed point.
  template <typename A>
  T dG(const A& a) const {
    return 2.0 * (P(a) * dP(a) + Q(a) * dQ(a));
  }
  // G(a) - target and dG/da together, P and Q formed once: the same values,
  // bit for bit, as G(a) - target and dG(a).
  template <typename A>
  void GMinusAndSlope(const A& a, double target, T* value, T* slope) const {
    const T p = P(a);
    const T q = Q(a);
    *value = p * p + q * q - target;
    *slope = 2.0 * (p * dP(a) + q * dQ(a));
  }
  // d2G/da2 = 2 (P'^2 + P P'' + Q'^2 + Q Q'') with P'' = 2 k2 (+ 6 k5 a +
  // 12 k7 a^2), Q'' = 6 k4 a (+ 20 k6 a^3).
  template <typename A>
  T d2G(const A& a) const {
    const T dp = dP(a);
    const T dq = dQ(a);
    if (higher_order) {
      const T ddp = 2.0 * k2 + (6.0 * k5 + 12.0 * k7 * a) * a;
      const T ddq = (6.0 * k4 + 20.0 * k6 * a * a) * a;
      return 2.0 * (dp * dp + P(a) * ddp + dq * dq + Q(a) * ddq);
    }
    return 2.0 * (dp * dp + P(a) * (2.0 * k2) + dq * dq + Q(a) * (6.0 * k4 * a));
  }

  // h(a) = (dG/da) / a = 2 c2 + 3 c3 a + 4 c4 a^2 + 5 c5 a^3 + 6 c6 a^4
  // + 7 c7 a^5 + 8 c8 a^6 + 10 c10 a^8, written through P and Q for conditioning; its
  // positive roots are the turning points of G.
  T h(const T& a) const { return 2.0 * (PPerA(a) * dP(a) + QPerA(a) * dQ(a)); }
  T dh(const T& a) const {
    if (higher_order) {
      const T a2 = a * a;
      return 3.0 * c3() + a * (8.0 * c4() + a * (15.0 * c5() + 24.0 * c6() * a)) +
             a2 * a2 * (35.0 * c7() + a * (48.0 * c8() + 80.0 * c10() * a2));
    }
    return 2.0 *
           (3.0 * k1 * k2 + 4.0 * k2 * k2 * a + 8.0 * k3 * k4 * a + 12.0 * k4 * k4 * a * a * a);
  }
  T d2h(const T& a) const {
    if (higher_order) {
      const T a2 = a * a;
      return 8.0 * c4() + a * (30.0 * c5() + 72.0 * c6() * a) +
             a2 * a * (140.0 * c7() + a * (240.0 * c8() + 560.0 * c10() * a2));
    }
    return 2.0 * (4.0 * k2 * k2 + 8.0 * k3 * k4 + 36.0 * k4 * k4 * a * a);
  }

  // Coefficients of G = c10 a^10 + c8 a^8 + c7 a^7 + c6 a^6 + c5 a^5 + c4 a^4
  // + c3 a^3 + c2 a^2 (a sextic for the chapter's member: c5 = c7 = c8 = c10 = 0).
  T c2() const { return k1 * k1 + k3 * k3; }
  T c3() const { return 2.0 * k1 * k2; }
  T c4() const {
    if (higher_order) return k2 * k2 + 2.0 * k3 * k4 + 2.0 * k1 * k5;
    return k2 * k2 + 2.0 * k3 * k4;
  }
  T c5() const { return higher_order ? T(2.0 * (k1 * k7 + k2 * k5)) : T(0.0); }
  T c6() const {
    if (higher_order) return k4 * k4 + k5 * k5 + 2.0 * (k2 * k7 + k3 * k6);
    return k4 * k4;
  }
  T c7() const { return higher_order ? T(2.0 * k5 * k7) : T(0.0); }
  T c8() const { return higher_order ? T(k7 * k7 + 2.0 * k4 * k6) : T(0.0); }
  T c10() const { return higher_order ? T(k6 * k6) : T(0.0); }
  // c_n at index n, n = 0..10 (c0 = c1 = c9 = 0).
  std::array<T, 11> Coefficients() const {
    return {T(0.0), T(0.0), c2(), c3(), c4(), c5(), c6(), c7(), c8(), T(0.0), c10()};
  }
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_RESPONSE_MODEL_H_
