// The stable fixed point on a named branch, found in double precision, and its
// lift to any scalar type by the implicit function theorem.
//
// Structure used (docs/model.md, "Stability and folds"): dG/da = a h(a) with the
// quartic h(a) = 6 c6 a^4 + 4 c4 a^2 + 3 c3 a + 2 c2, c2, c3, c6 >= 0. By
// Descartes' rule h has no positive root when c4 >= 0 and zero or two when
// c4 < 0. So G has at most two turning points on a > 0: a local maximum at
// a_lower_end (where the lower stable branch ends; the jump-up of an amplitude
// sweep) and a local minimum at a_upper_end > a_lower_end (where the upper
// branch ends). G is increasing on (0, a_lower_end) and on (a_upper_end, inf),
// so each stable branch is a bracket on which G - a_base^2 is monotone, and the
// safeguarded Newton iteration from the measured amplitude finds exactly the
// root of that branch; the unstable middle root is never returned.
#ifndef DWELLFIT_RESIDUALS_MODEL_STABLE_ROOT_H_
#define DWELLFIT_RESIDUALS_MODEL_STABLE_ROOT_H_

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/residuals/model/amplitude_roots.h"
#include "dwellfit/residuals/model/bracketed_newton.h"
#include "dwellfit/residuals/model/response_model.h"

namespace dwellfit {

// The stable branch a dwell point sits on. kLower is the smallest positive
// root, kUpper the largest; kOnly marks a point measured where the response is
// single-valued: if the model has two stable roots there, the one nearer the
// measured amplitude is used.
enum class Branch { kLower, kUpper, kOnly };

inline const char* BranchName(Branch branch) {
  constexpr const char* kNames[] = {"lower", "upper", "only"};
  return kNames[static_cast<int>(branch)];
}

// Turning points of G(a) on a > 0 at one drive frequency.
struct TurningPoints {
  bool exist = false;
  double a_lower_end = 0.0;  // local maximum of G: the lower branch ends here
  double a_upper_end = 0.0;  // local minimum of G: the upper branch ends here
  // Where the upper branch ends going up: a third turning point (a local
  // maximum of G, only with terms beyond the chapter's), else infinity.
  // Where G folds nowhere within a correction's limit (CorrectionLimit), the
  // first turning point beyond it, if any: the single branch ends there.
  double a_upper_limit = std::numeric_limits<double>::infinity();
};

// The amplitude up to which terms that correct the first-order model (the
// second-order form, ResponseCoefficients::correction) hold: with k4 k6 < 0,
// Q / a = k3 + k4 a^2 + k6 a^4 shifts the backbone monotonically in a^2 only
// up to a^2 = -k4 / (2 k6), where d(Q/a)/d(a^2) = k4 + 2 k6 a^2 = 0; beyond it
// the correction would outweigh and reverse the first-order term it corrects
// (on a softening cubic, a second fold pair that is no response of the
// structure). Infinity for the chapter's member and the family's own terms.
inline double CorrectionLimit(const ResponseCoefficients<double>& k) {
  if (!k.correction || !(k.k4 * k.k6 < 0.0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(-k.k4 / (2.0 * k.k6));
}

namespace internal {

// Doubles `hi` until `positive(hi)` holds; returns NaN after too many tries.
template <typename Predicate>
double ExpandUntil(double hi, const Predicate& positive) {
  for (int i = 0; i < 2100 && std::isfinite(hi); ++i) {
    if (positive(hi)) return hi;
    hi *= 2.0;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// The turning points of a model with terms beyond the chapter's (k.higher_order),
// where h = (dG/da)/a is of degree eight and may have four positive roots:
// the positive real roots of h (companion matrix, in the variable a / a_s
// with a_s = (c2 / c_top)^(1 / top), c_top the leading coefficient of G),
// polished by Newton steps on h. G rises from 0 to the first (a local
// maximum: a_lower_end) and from the second (a local minimum: a_upper_end) to
// the third (a_upper_limit) or on: the branches of the first fold pair, the
// chapter's two. A branch beyond a second fold pair has no name and is never
// returned; where the terms are a second-order correction (docs/model.md),
// that pair lies beyond the correction's validity (a softening cubic with the
// quintic k6 > 0 that the correction adds folds back at large amplitude).
// h(a) = (dG/da) / a = sum_m b_m a^m of G's coefficients `c`:
// b_m = (m + 2) c_(m+2), m = 0..8.
inline std::array<double, 9> SlopeCoefficients(const std::array<double, 11>& c) {
  std::array<double, 9> b;
  for (int m = 0; m < 9; ++m) b[m] = (m + 2) * c[m + 2];
  return b;
}

inline TurningPoints FindTurningPointsOfFamily(const ResponseCoefficients<double>& k) {
  TurningPoints tp;
  const std::array<double, 11> c = k.Coefficients();
  int top = 10;
  while (top > 2 && c[top] == 0.0) --top;
  if (top <= 3 || !(c[2] > 0.0)) return tp;  // G = c2 a^2 + c3 a^3 rises on a > 0
  const double scale = std::pow(c[2] / std::abs(c[top]), 1.0 / (top - 2));
  // h in x = a / scale, divided by 2 c2.
  const std::array<double, 9> h = SlopeCoefficients(c);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(top - 1);
  for (int m = 0; m <= top - 2; ++m) b[m] = h[m] * std::pow(scale, m) / (2.0 * c[2]);
  std::vector<double> ends;
  for (const std::complex<double>& z : ScaledPolynomialRoots(b, scale)) {
    if (!(z.real() > 0.0) || !IsRealRoot(z)) continue;
    double a = z.real();
    for (int i = 0; i < 4; ++i) {
      const double slope = k.dh(a);
      if (!(slope != 0.0) || !std::isfinite(slope)) break;
      a -= k.h(a) / slope;
    }
    if (a > 0.0 && std::isfinite(a)) ends.push_back(a);
  }
  std::sort(ends.begin(), ends.end());
  // The fold pair must lie within a correction's limit; the next turning
  // point bounds its upper branch wherever it lies.
  const double limit = CorrectionLimit(k);
  if (ends.size() < 2 || ends[1] > limit) {
    if (ends.size() >= 2) tp.a_upper_limit = ends[0];
    return tp;
  }
  tp.a_lower_end = ends[0];
  tp.a_upper_end = ends[1];
  if (ends.size() > 2) tp.a_upper_limit = ends[2];
  tp.exist = true;
  return tp;
}

}  // namespace internal

// The turning points of G on a > 0; `branch` names the one wanted (kLower:
// a_lower_end alone, kUpper: a_upper_end alone, the other left 0; kOnly:
// both). A turning point computed is the same value either way. A member
// with terms beyond the chapter's has both computed (FindTurningPointsOfFamily).
inline TurningPoints FindTurningPoints(const ResponseCoefficients<double>& k,
                                       Branch branch = Branch::kOnly) {
  if (k.higher_order) return internal::FindTurningPointsOfFamily(k);
  TurningPoints tp;
  const double c4 = k.c4();
  const double c6 = k.c6();
  if (!(c6 > 0.0) || !(c4 < 0.0)) return tp;
  auto h = [&k](double a, double* value, double* slope) {
    *value = k.h(a);
    *slope = k.dh(a);
  };
  // h' has its minimum on a >= 0 at a_inflection.
  auto dh = [&k](double a, double* value, double* slope) {
    *value = k.dh(a);
    *slope = k.d2h(a);
  };
  const double a_inflection = std::sqrt(-c4 / (9.0 * c6));
  double v, s;
  dh(a_inflection, &v, &s);
  if (v >= 0.0) return tp;  // h increasing from h(0) = 2 c2 >= 0: G monotone
  const double dh_hi = internal::ExpandUntil(2.0 * a_inflection, [&](double a) {
    dh(a, &v, &s);
    return v > 0.0;
  });
  if (!std::isfinite(dh_hi)) return tp;
  const double a_h_min = BracketedNewton(dh, a_inflection, dh_hi, dh_hi);
  h(a_h_min, &v, &s);
  if (!(v < 0.0)) return tp;  // h >= 0 everywhere: no fold at this frequency
  const double h_hi = internal::ExpandUntil(2.0 * a_h_min, [&](double a) {
    h(a, &v, &s);
    return v > 0.0;
  });
  if (!std::isfinite(h_hi)) return tp;
  if (branch != Branch::kUpper) tp.a_lower_end = BracketedNewton(h, 0.0, a_h_min, 0.5 * a_h_min);
  if (branch != Branch::kLower) tp.a_upper_end = BracketedNewton(h, a_h_min, h_hi, h_hi);
  tp.exist = std::isfinite(tp.a_lower_end) && std::isfinite(tp.a_upper_end);
  return tp;
}

enum class RootStatus {
  kOnBranch,   // a solves G(a) = a_base^2 on the requested branch
  kBranchEnd,  // the requested branch does not reach a_base here; a is the
               // turning point where it ends (a continuous extension)
  kFailed,     // no root could be bracketed (parameters not finite, eta_e = 0)
};

struct StableRoot {
  double a = 0.0;
  RootStatus status = RootStatus::kFailed;
  Branch branch = Branch::kOnly;  // the branch actually used (kOnly: G monotone)
};

// The stable root of G(a) = a_base^2 on `branch`, started from `a_guess`
// (normally the measured amplitude).
inline StableRoot SolveStableRoot(const ResponseCoefficients<double>& k, double a_base,
                                  Branch branch, double a_guess) {
  StableRoot root;
  const double target = a_base * a_base;
  if (!(target > 0.0) || !std::isfinite(k.k1 + k.k2 + k.k3 + k.k4 + k.k5 + k.k6 + k.k7))
    return root;
  auto residual = [&k, target](double a, double* value, double* slope) {
    k.GMinusAndSlope(a, target, value, slope);
  };
  auto upper_bracket_end = [&](double start) {
    return internal::ExpandUntil(start, [&](double a) { return k.G(a) > target; });
  };
  const double guess = a_guess > 0.0 ? a_guess : std::numeric_limits<double>::quiet_NaN();
  const TurningPoints tp = FindTurningPoints(k, branch);
  if (!tp.exist) {
    // G rises up to a_upper_limit (a turning point beyond a correction's
    // limit) or without end: the branch ends there if G stays below the level.
    if (std::isfinite(tp.a_upper_limit) && !(k.G(tp.a_upper_limit) > target)) {
      return {tp.a_upper_limit, RootStatus::kBranchEnd, Branch::kOnly};
    }
    const double hi = std::isfinite(tp.a_upper_limit)
                          ? tp.a_upper_limit
                          : upper_bracket_end(guess > 0.0 ? guess : std::sqrt(a_base));
    if (!std::isfinite(hi)) return root;
    root.a = BracketedNewton(residual, 0.0, hi, guess);
    root.status = std::isfinite(root.a) ? RootStatus::kOnBranch : RootStatus::kFailed;
    return root;
  }
  // Whether each branch reaches a_base, once each (the branch whose turning
  // point was not found is never asked for).
  // An upper branch capped by a third turning point (terms beyond the
  // chapter's) reaches a_base only if its top, G(a_upper_limit), is above it;
  // if not, it ends there.
  const bool capped = std::isfinite(tp.a_upper_limit);
  const bool below_top = !capped || k.G(tp.a_upper_limit) > target;
  const bool lower_exists = branch != Branch::kUpper && k.G(tp.a_lower_end) > target;
  const bool upper_exists = branch != Branch::kLower && k.G(tp.a_upper_end) < target && below_top;
  // The root on branch `on` (kLower or kUpper), or the turning point where it ends.
  auto solve = [&](Branch on) {
    const bool upper = on == Branch::kUpper;
    const double end = upper ? (below_top ? tp.a_upper_end : tp.a_upper_limit) : tp.a_lower_end;
    if (!(upper ? upper_exists : lower_exists)) return StableRoot{end, RootStatus::kBranchEnd, on};
    const double hi =
        upper ? (capped ? tp.a_upper_limit : upper_bracket_end(std::max(2.0 * end, guess))) : end;
    if (!std::isfinite(hi)) return StableRoot{0.0, RootStatus::kFailed, on};
    return StableRoot{BracketedNewton(residual, upper ? end : 0.0, hi, guess),
                      RootStatus::kOnBranch, on};
  };
  if (branch != Branch::kOnly) {
    root = solve(branch);
  } else if (lower_exists && upper_exists) {
    const StableRoot l = solve(Branch::kLower);
    const StableRoot u = solve(Branch::kUpper);
    root = std::abs(l.a - a_guess) <= std::abs(u.a - a_guess) ? l : u;
  } else {
    root = solve(lower_exists ? Branch::kLower : Branch::kUpper);
  }
  if (!std::isfinite(root.a)) root.status = RootStatus::kFailed;
  return root;
}

namespace internal {

// Certificate that a root r > 0 of G = a_base^2 lies on `branch`, from the
// quartic h = (dG/da)/a = 6 c6 a^4 + 4 c4 a^2 + 3 c3 a + 2 c2 (c2, c6 >= 0).
// Where c3 >= 0 (mu1 mu2 >= 0), h >= 2 c2 + 3 c3 a_min + min q over an
// interval starting at a_min, q(a) = 6 c6 a^4 + 4 c4 a^2, whose minimum on
// a >= 0 is -(2/3) c4^2 / c6 at a^2 = -c4 / (3 c6) when c4 < 0:
//   upper: h > 0 on [r, inf) (bound with a_min = r), so G rises past r: r
//     is the largest root, and stable. Failing that, h(r) > 0, h'(r) >= 0
//     and h''(r) >= 0 also suffice: h'' = 72 c6 a^2 + 8 c4 grows with a, so
//     h' and then h grow on [r, inf).
//   lower: h > 0 on (0, r] (bound with a_min = 0), so G rises on (0, r]: r
//     is the smallest root, and stable.
inline bool CertifiedOnBranch(const ResponseCoefficients<double>& k, double r, Branch branch) {
  if (branch != Branch::kUpper && branch != Branch::kLower) return false;
  const double c2 = k.c2();
  const double c3 = k.c3();
  const double c4 = k.c4();
  const double c6 = k.c6();
  auto q = [c4, c6](double a) { return (6.0 * c6 * a * a + 4.0 * c4) * a * a; };
  // a^2 where q has its minimum on a >= 0 (0 when q only grows).
  const double a2_min = c4 < 0.0 && c6 > 0.0 ? -c4 / (3.0 * c6) : 0.0;
  // (c6 = k4^2 = 0 makes c4 = k2^2 >= 0: q never falls without bound.)
  if (branch == Branch::kUpper) {
    if (c3 >= 0.0 && (c6 > 0.0 || c4 >= 0.0)) {
      const double q_min = r * r >= a2_min ? q(r) : q(std::sqrt(a2_min));
      if (2.0 * c2 + 3.0 * c3 * r + q_min > 0.0) return true;
    }
    return k.h(r) > 0.0 && k.dh(r) >= 0.0 && k.d2h(r) >= 0.0;
  }
  if (!(c3 >= 0.0) || !(c6 > 0.0 || c4 >= 0.0)) return false;
  const double q_min = r * r <= a2_min ? q(r) : q(std::sqrt(a2_min));
  return 2.0 * c2 + q_min > 0.0;
}

// The same certificate for a member with terms beyond the chapter's, from
// h(a) = sum_m b_m a^m, b_m = (m + 2) c_(m+2), m = 0..8 (b_0 = 2 c2 >= 0):
//   lower: h > 0 on (0, r]: b_0 + sum over m >= 1 of min(0, b_m) r^m > 0
//     (each negative term is most negative at a = r); G rises on (0, r], so
//     r lies below every turning point: the lower branch's root, wherever
//     the fold pair lies (within CorrectionLimit or not).
//   upper: h has at most two positive roots (Descartes: at most two sign
//     changes among b_0..b_8), so G folds at most once, and h > 0 on
//     [r, inf) (h's Taylor coefficients at r all >= 0, h(r) > 0): r lies past
//     every turning point, on the upper branch; and r within
//     CorrectionLimit, so that the fold pair below it is named.
//   only: h has no positive root (no sign change): G rises everywhere and r
//     is its one root.
inline bool CertifiedOnBranchOfFamily(const ResponseCoefficients<double>& k, double r,
                                      Branch branch) {
  std::array<double, 9> b = SlopeCoefficients(k.Coefficients());
  int sign_changes = 0;
  double last = b[0];
  for (int m = 1; m < 9; ++m) {
    if (b[m] == 0.0) continue;
    if ((b[m] < 0.0) != (last < 0.0)) ++sign_changes;
    last = b[m];
  }
  if (branch == Branch::kOnly) return sign_changes == 0 && b[0] > 0.0;
  if (branch == Branch::kLower) {
    double bound = b[0], power = 1.0;
    for (int m = 1; m < 9; ++m) {
      power *= r;
      bound += std::min(0.0, b[m]) * power;
    }
    return bound > 0.0;
  }
  if (sign_changes > 2 || r > CorrectionLimit(k)) return false;
  // Taylor coefficients at r by repeated Horner steps: b_j becomes h^(j)(r) / j!.
  for (int i = 0; i < 8; ++i) {
    for (int j = 7; j >= i; --j) b[j] += r * b[j + 1];
  }
  if (!(b[0] > 0.0)) return false;
  return std::all_of(b.begin(), b.end(), [](double x) { return x >= 0.0; });
}

}  // namespace internal

// The same root as SolveStableRoot, faster where the measured amplitude is
// near its branch: plain Newton from `a_guess`, accepted only with a
// certificate that the root lies on `branch` (internal::CertifiedOnBranch,
// or CertifiedOnBranchOfFamily with terms beyond the chapter's, which also
// certifies the one root of a G without fold for kOnly); anything else falls
// back to SolveStableRoot. The returned `branch` is the
// requested one even where G is monotone.
inline StableRoot SolveStableRootNear(const ResponseCoefficients<double>& k, double a_base,
                                      Branch branch, double a_guess) {
  // The sextic's certificate, or the family's (which also certifies a
  // single-valued G's one root); anything uncertified brackets its branch
  // between turning points.
  if (a_guess > 0.0 && (branch != Branch::kOnly || k.higher_order)) {
    const double target = a_base * a_base;
    double a = a_guess;
    for (int i = 0; i < 30; ++i) {
      double value, slope;
      k.GMinusAndSlope(a, target, &value, &slope);
      if (!(slope > 0.0)) break;
      const double step = value / slope;
      a -= step;
      if (!(a > 0.0) || !std::isfinite(a)) break;
      if (std::abs(step) <= 4.0 * std::numeric_limits<double>::epsilon() * a) {
        const bool certified = k.higher_order ? internal::CertifiedOnBranchOfFamily(k, a, branch)
                                              : internal::CertifiedOnBranch(k, a, branch);
        if (certified) return {a, RootStatus::kOnBranch, branch};
        break;
      }
    }
  }
  return SolveStableRoot(k, a_base, branch, a_guess);
}

// Lifts a root found in double to scalar T (double or ceres::Jet) by one Newton
// step in T arithmetic from the converged root: the value gains one more
// Newton step, and the derivative part is exactly -F_p / F_a, the implicit
// function theorem for F(a; p) = 0. On a branch, F = G - a_base^2; at a branch
// end, F = dG/da (the turning point moves with the parameters).
template <typename T>
T LiftRoot(const ResponseCoefficients<T>& k, double a_base, const StableRoot& root) {
  const double a0 = root.a;  // a constant: its Jet would carry a zero derivative
  if (root.status == RootStatus::kBranchEnd) return a0 - k.dG(a0) / k.d2G(a0);
  T value, slope;
  k.GMinusAndSlope(a0, a_base * a_base, &value, &slope);
  return a0 - value / slope;
}

inline double ScalarPart(double x) { return x; }
template <typename J>
auto ScalarPart(const J& x) -> decltype(x.a) {
  return x.a;
}

// The coefficients' scalar parts (themselves for double).
template <typename T>
ResponseCoefficients<double> ScalarCoefficients(const ResponseCoefficients<T>& k) {
  ResponseCoefficients<double> scalar{ScalarPart(k.k1), ScalarPart(k.k2), ScalarPart(k.k3),
                                      ScalarPart(k.k4)};
  scalar.k5 = ScalarPart(k.k5);
  scalar.k6 = ScalarPart(k.k6);
  scalar.k7 = ScalarPart(k.k7);
  scalar.higher_order = k.higher_order;
  scalar.correction = k.correction;
  return scalar;
}

// The model's amplitude at one dwell (double precision convenience).
inline StableRoot ModelAmplitude(ModelForm form, const ParameterVector& p, double omega_drive_rad_s,
                                 double a_base, Branch branch, double a_guess) {
  const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), omega_drive_rad_s);
  StableRoot root = SolveStableRoot(k, a_base, branch, a_guess);
  if (root.status != RootStatus::kFailed) root.a = LiftRoot(k, a_base, root);
  return root;
}

// ModelAmplitude through SolveStableRootNear: the same amplitude, faster
// where `a_guess` (a measured amplitude) lies near its branch; the returned
// `branch` is the requested one (see SolveStableRootNear).
inline StableRoot ModelAmplitudeNear(ModelForm form, const ParameterVector& p,
                                     double omega_drive_rad_s, double a_base, Branch branch,
                                     double a_guess) {
  const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), omega_drive_rad_s);
  StableRoot root = SolveStableRootNear(k, a_base, branch, a_guess);
  if (root.status != RootStatus::kFailed) root.a = LiftRoot(k, a_base, root);
  return root;
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_STABLE_ROOT_H_
