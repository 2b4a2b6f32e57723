#include "dwellfit/estimator/traces/strain_gauge.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>

#include "boost/math/tools/roots.hpp"
#include "dwellfit/estimator/common/string_printf.h"

namespace dwellfit {
namespace {

// beta_n L of the first three modes: roots of cos(x) cosh(x) = -1
// (cantilever) and cos(x) cosh(x) = 1 (clamped-clamped).
constexpr double kCantileverBetaL[3] = {1.8751040687119611, 4.6940911329741746, 7.8547574382376126};
constexpr double kClampedBetaL[3] = {4.7300407448627040, 7.8532046240958376, 10.995607838001671};

struct RawMode {
  double beta;   // 1/m
  double sigma;  // the sinh/sin coefficient
  // phi, phi', phi'' unnormalised at x [m].
  double Value(double x) const {
    const double b = beta * x;
    return std::cosh(b) - std::cos(b) - sigma * (std::sinh(b) - std::sin(b));
  }
  double Slope(double x) const {
    const double b = beta * x;
    return beta * (std::sinh(b) + std::sin(b) - sigma * (std::cosh(b) - std::cos(b)));
  }
  double Curvature(double x) const {
    const double b = beta * x;
    return beta * beta * (std::cosh(b) + std::cos(b) - sigma * (std::sinh(b) + std::sin(b)));
  }
};

RawMode MakeRawMode(const StrainGaugeOptions& options) {
  const bool cantilever = options.boundary == BeamBoundary::kCantilever;
  const double beta_l = (cantilever ? kCantileverBetaL : kClampedBetaL)[options.mode - 1];
  const double sigma =
      cantilever ? (std::cosh(beta_l) + std::cos(beta_l)) / (std::sinh(beta_l) + std::sin(beta_l))
                 : (std::cosh(beta_l) - std::cos(beta_l)) / (std::sinh(beta_l) - std::sin(beta_l));
  return {beta_l / options.length_m, sigma};
}

// max |phi| over the span: a grid, then the grid's best point refined by
// Newton on phi' (phi'' != 0 at an interior maximum).
double LargestDeflection(const RawMode& mode, double length) {
  constexpr int kGrid = 2000;
  double best_x = 0.0;
  for (int i = 0; i <= kGrid; ++i) {
    const double x = length * i / kGrid;
    if (std::abs(mode.Value(x)) > std::abs(mode.Value(best_x))) best_x = x;
  }
  if (best_x > 0.0 && best_x < length) {
    for (int i = 0; i < 5; ++i) best_x -= mode.Slope(best_x) / mode.Curvature(best_x);
  }
  return std::abs(mode.Value(best_x));
}

}  // namespace

bool StrainGaugeOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& text) {
    *error = text;
    return false;
  };
  if (mode < 1 || mode > 3) return fail(StringPrintf("mode must be 1, 2 or 3, got %d", mode));
  for (double value : {length_m, thickness_m, excitation_v, gain, gauge_factor}) {
    if (!(std::isfinite(value) && value > 0.0)) {
      return fail("length_m, thickness_m, excitation_v, gain and gauge_factor must be positive");
    }
  }
  if (!(gauge_position_m >= 0.0 && gauge_position_m <= length_m)) {
    return fail(StringPrintf("gauge_position_m %g must lie on the beam, in [0, %g]",
                             gauge_position_m, length_m));
  }
  if (ModeShapeAt(*this).curvature_per_m2 == 0.0) {
    return fail("the mode has no curvature at the gauge; move the gauge");
  }
  return true;
}

ModeShapeAtGauge ModeShapeAt(const StrainGaugeOptions& options) {
  const RawMode mode = MakeRawMode(options);
  const double scale = LargestDeflection(mode, options.length_m);
  return {mode.Slope(options.gauge_position_m) / scale,
          mode.Curvature(options.gauge_position_m) / scale};
}

StrainGauge::StrainGauge(const StrainGaugeOptions& options)
    : shape_(ModeShapeAt(options)),
      c_(0.5 * options.thickness_m),
      volts_per_strain_(options.excitation_v * options.gain * options.gauge_factor / 4.0) {}

double StrainGauge::StrainFromDisplacement(double u_m) const {
  const double slope = u_m * shape_.slope_per_m;
  return c_ * u_m * shape_.curvature_per_m2 / std::pow(1.0 + slope * slope, 1.5);
}

double StrainGauge::VoltageFromDisplacement(double u_m) const {
  return volts_per_strain_ * StrainFromDisplacement(u_m);
}

bool StrainGauge::DisplacementFromVoltage(double volts, double* u_m) const {
  const double strain = volts / volts_per_strain_;
  const double p = std::abs(shape_.slope_per_m);
  // Where e(u) peaks: |u phi'| = 1/sqrt(2) (infinite when phi' = 0).
  const double u_peak = p > 0.0 ? 1.0 / (std::sqrt(2.0) * p) : 1e300;
  if (p > 0.0 && std::abs(strain) > std::abs(StrainFromDisplacement(u_peak))) return false;
  if (!std::isfinite(strain)) return false;
  const double guess = strain / (c_ * shape_.curvature_per_m2);
  auto residual = [this, strain](double u) {
    const double s = u * shape_.slope_per_m;
    const double q = 1.0 + s * s;
    const double de_du = c_ * shape_.curvature_per_m2 * (1.0 - 2.0 * s * s) / std::pow(q, 2.5);
    return std::make_tuple(StrainFromDisplacement(u) - strain, de_du);
  };
  std::uintmax_t iterations = 50;
  const double bound = std::min(u_peak, 1e300);
  *u_m = boost::math::tools::newton_raphson_iterate(residual, std::clamp(guess, -bound, bound),
                                                    -bound, bound, 50, iterations);
  return std::isfinite(*u_m);
}

}  // namespace dwellfit
