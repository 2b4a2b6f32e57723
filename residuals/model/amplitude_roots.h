// All roots of the frequency-response polynomial (3.11) at one dwell, by
// Eigen's companion-matrix polynomial solver, and what the chapter's
// all-roots algorithm (section 3.2.2) reads from them: the stable positive
// real roots, and which pair of roots is the saddle and the node of a fold.
//
//   F(a) = G(a) - a_base^2 = c10 a^10 + c8 a^8 + c7 a^7 + c6 a^6 + c5 a^5
//          + c4 a^4 + c3 a^3 + c2 a^2 - a_base^2
//
// a sextic for the chapter's member (c5 = c8 = c10 = 0; docs/model.md, "Fixed
// points"), of degree ten with the terms k5, k6 and k7. The polynomial is
// solved in the scaled variable x = a / a_scale (a_scale: an amplitude of the
// data, e.g. the measured one), so its coefficients c_n a_scale^n / a_base^2
// are of order one. Roots found real are polished by Newton steps on G in
// double, which the companion matrix leaves at some 1e-12 relative.
#ifndef DWELLFIT_RESIDUALS_MODEL_AMPLITUDE_ROOTS_H_
#define DWELLFIT_RESIDUALS_MODEL_AMPLITUDE_ROOTS_H_

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/residuals/model/response_model.h"
#include "unsupported/Eigen/Polynomials"

namespace dwellfit {

// A root counts as real when its imaginary part is below this fraction of
// its modulus (the companion matrix resolves simple roots to ~1e-12 and a
// double root to ~1e-8).
inline constexpr double kRealRootTolerance = 1e-7;

// The roots of the polynomial sum_n b[n] x^n (b[n] = coefficient of x^n),
// complex, in no particular order, after dropping vanishing leading
// coefficients; `x_scale` multiplies each root. Empty when a coefficient is
// not finite or the polynomial is constant.
inline std::vector<std::complex<double>> ScaledPolynomialRoots(Eigen::VectorXd b, double x_scale) {
  if (!b.allFinite()) return {};
  Eigen::Index degree = b.size() - 1;
  while (degree > 0 && b[degree] == 0.0) --degree;
  if (degree < 1) return {};
  Eigen::PolynomialSolver<double, Eigen::Dynamic> solver;
  solver.compute(Eigen::VectorXd(b.head(degree + 1)));
  std::vector<std::complex<double>> roots;
  for (Eigen::Index i = 0; i < solver.roots().size(); ++i) {
    roots.push_back(solver.roots()[i] * x_scale);
  }
  return roots;
}

// The roots of F(a) = G(a) - a_base^2 in a, complex, in no particular order;
// fewer than the degree where the leading coefficients vanish. Empty when the
// coefficients are not finite or the polynomial is constant.
inline std::vector<std::complex<double>> AmplitudeRoots(const ResponseCoefficients<double>& k,
                                                        double a_base, double a_scale) {
  const double target = a_base * a_base;
  const std::array<double, 11> c = k.Coefficients();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(k.higher_order ? 11 : 7);
  b[0] = -1.0;
  double s = 1.0;
  for (int n = 2; n < b.size(); ++n) {
    s *= n == 2 ? a_scale * a_scale : a_scale;
    b[n] = c[n] * (s / target);
  }
  return ScaledPolynomialRoots(b, a_scale);
}

inline bool IsRealRoot(const std::complex<double>& z) {
  return std::abs(z.imag()) <= kRealRootTolerance * std::abs(z);
}

// Newton steps on G(a) = a_base^2 in double from a real root `a`, while they
// shrink; returns the polished root.
inline double PolishRealRoot(const ResponseCoefficients<double>& k, double a_base, double a) {
  const double target = a_base * a_base;
  double last_step = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    const double slope = k.dG(a);
    if (!(slope != 0.0) || !std::isfinite(slope)) break;
    const double step = (k.G(a) - target) / slope;
    if (!(std::abs(step) < last_step)) break;
    a -= step;
    last_step = std::abs(step);
    if (last_step <= 4.0 * std::numeric_limits<double>::epsilon() * std::abs(a)) break;
  }
  return a;
}

// The positive real roots of `roots`, polished and in increasing order.
inline std::vector<double> PositiveRealRoots(const ResponseCoefficients<double>& k, double a_base,
                                             const std::vector<std::complex<double>>& roots) {
  std::vector<double> real;
  for (const std::complex<double>& z : roots) {
    if (z.real() > 0.0 && IsRealRoot(z)) real.push_back(PolishRealRoot(k, a_base, z.real()));
  }
  std::sort(real.begin(), real.end());
  return real;
}

// The stable root nearest `a_measured` (section 3.2.2): among the positive
// real roots, the stable ones (dG/da > 0: the smallest and the largest of
// three, and every other one of five) and the nearest of them. False when there is none.
inline bool NearestStableRoot(const ResponseCoefficients<double>& k, double a_base,
                              double a_measured, double* root) {
  const std::vector<double> real =
      PositiveRealRoots(k, a_base, AmplitudeRoots(k, a_base, a_measured));
  bool found = false;
  for (double a : real) {
    if (!(k.dG(a) > 0.0)) continue;  // the saddle (unstable middle root)
    if (!found || std::abs(a - a_measured) < std::abs(*root - a_measured)) *root = a;
    found = true;
  }
  return found;
}

// The two roots that meet at a fold (section 3.2.3: "the saddle and the
// node"): for the end of the upper branch (a jump-down) the two largest
// positive real roots when there are three or more, for the end of the lower branch
// (a jump-up) the two smallest; where there are fewer, the pair has already
// turned complex, and it is the conjugate pair whose upper member is nearest
// `a_jump` (the measured amplitude before the jump). False when there is no
// such pair.
inline bool FoldRootPair(const std::vector<std::complex<double>>& roots, bool upper_branch_end,
                         double a_jump, std::complex<double>* first, std::complex<double>* second) {
  std::vector<std::complex<double>> real;
  const std::complex<double>* nearest_complex = nullptr;
  for (const std::complex<double>& z : roots) {
    if (IsRealRoot(z)) {
      if (z.real() > 0.0) real.emplace_back(z.real(), 0.0);
    } else if (z.imag() > 0.0 && (nearest_complex == nullptr ||
                                  std::abs(z - a_jump) < std::abs(*nearest_complex - a_jump))) {
      nearest_complex = &z;
    }
  }
  std::sort(real.begin(), real.end(),
            [](const std::complex<double>& x, const std::complex<double>& y) {
              return x.real() < y.real();
            });
  if (real.size() >= 3) {
    const size_t i = upper_branch_end ? real.size() - 2 : 0;
    *first = real[i];
    *second = real[i + 1];
    return true;
  }
  if (nearest_complex == nullptr) return false;
  *first = *nearest_complex;
  *second = std::conj(*nearest_complex);
  return true;
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_AMPLITUDE_ROOTS_H_
