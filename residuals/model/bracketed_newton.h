// Safeguarded Newton iteration on a bracket (Newton steps that would leave the
// bracket, or that do not halve the step, are replaced by bisection). It cannot
// diverge: the bracket shrinks at every step and always holds a sign change.
#ifndef DWELLFIT_RESIDUALS_MODEL_BRACKETED_NEWTON_H_
#define DWELLFIT_RESIDUALS_MODEL_BRACKETED_NEWTON_H_

#include <algorithm>
#include <cmath>
#include <limits>

namespace dwellfit {

// `f(x, &value, &slope)` evaluates the function and its derivative. Requires
// f(lo) and f(hi) of opposite sign (or one of them zero); `x0` is the starting
// point, clamped into [lo, hi]. Returns a root in [lo, hi] to within a few ulps
// of x, or NaN when the bracket does not hold a sign change.
template <typename Function>
double BracketedNewton(const Function& f, double lo, double hi, double x0) {
  constexpr int kMaxIterations = 300;
  const double kTolerance = 4.0 * std::numeric_limits<double>::epsilon();
  double f_lo, f_hi, slope;
  f(lo, &f_lo, &slope);
  f(hi, &f_hi, &slope);
  if (f_lo == 0.0) return lo;
  if (f_hi == 0.0) return hi;
  if (!(f_lo * f_hi < 0.0)) return std::numeric_limits<double>::quiet_NaN();
  // Orient the bracket so that f(x_neg) < 0 < f(x_pos).
  double x_neg = f_lo < 0.0 ? lo : hi;
  double x_pos = f_lo < 0.0 ? hi : lo;
  double x =
      std::isfinite(x0) ? std::clamp(x0, std::min(lo, hi), std::max(lo, hi)) : 0.5 * (lo + hi);
  double step_before_last = std::abs(hi - lo);
  double last_step = step_before_last;
  double value;
  f(x, &value, &slope);
  for (int i = 0; i < kMaxIterations; ++i) {
    if (value == 0.0) return x;
    if (value < 0.0) {
      x_neg = x;
    } else {
      x_pos = x;
    }
    const bool newton_leaves_bracket =
        ((x - x_pos) * slope - value) * ((x - x_neg) * slope - value) > 0.0;
    const bool newton_too_slow = std::abs(2.0 * value) > std::abs(step_before_last * slope);
    step_before_last = last_step;
    if (newton_leaves_bracket || newton_too_slow || !std::isfinite(slope) || slope == 0.0) {
      last_step = 0.5 * (x_pos - x_neg);
      x = x_neg + last_step;
    } else {
      last_step = value / slope;
      x -= last_step;
    }
    if (std::abs(last_step) <= kTolerance * std::abs(x) ||
        std::abs(x_pos - x_neg) <= kTolerance * std::abs(x)) {
      return x;
    }
    f(x, &value, &slope);
  }
  return x;
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_BRACKETED_NEWTON_H_
