#include "dwellfit/estimator/analysis/modal_properties.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/model/equivalent_oscillator.h"
#include "dwellfit/residuals/model/response_model.h"

namespace dwellfit {
namespace {

constexpr double kZ95 = 1.959963984540054;

// q +/- z sqrt(g^T C g), g by central differences over the parameters C has.
template <typename Quantity>
void Band(const ParameterVector& p, const ParameterMatrix& covariance, Quantity q, double value,
          double* low, double* high) {
  Eigen::Matrix<double, kNumParameters, 1> gradient =
      Eigen::Matrix<double, kNumParameters, 1>::Zero();
  for (int j = 0; j < kNumParameters; ++j) {
    if (covariance(j, j) <= 0.0) continue;
    const double step = p[j] != 0.0 ? 1e-6 * std::abs(p[j]) : 1e-6 * std::sqrt(covariance(j, j));
    ParameterVector up = p, down = p;
    up[j] += step;
    down[j] -= step;
    gradient[j] = (q(up) - q(down)) / (2.0 * step);
  }
  const double half = kZ95 * std::sqrt(std::max(0.0, gradient.dot(covariance * gradient)));
  *low = value - half;
  *high = value + half;
}

}  // namespace

double ModalFrequency(ModelForm form, const ParameterVector& p, double a) {
  const double w = p[kNaturalFrequency];
  const EquivalentOscillator o = EquivalentOscillatorAt(form, p, a);
  const double mass = o.mass;
  const double stiffness = o.stiffness;
  double squared = stiffness / mass;
  // The second order's fixed point: its correction is of order a^4, small
  // beside the first order's, so a few steps settle it.
  for (int i = 0; form.second_order() && i < 50 && squared > 0.0; ++i) {
    const double g = p[kAlpha] - 2.0 * p[kDelta] * squared;
    const double d = 9.0 * squared - w * w;
    const double next = (stiffness + 0.75 * g * g * a * a * a * a / d) / mass;
    const bool settled = std::abs(next - squared) <= 1e-15 * std::abs(squared);
    squared = next;
    if (settled) break;
  }
  return squared > 0.0 ? std::sqrt(squared) : std::numeric_limits<double>::quiet_NaN();
}

double ModalDampingRatio(ModelForm form, const ParameterVector& p, double a) {
  // P / (a Omega / eta_e): mu1 + 4 mu2 a / (3 pi), or mu1 + mu3 a^2 / 4.
  const EquivalentOscillator o = EquivalentOscillatorAt(form, p, a);
  double damping = o.damping;
  const double omega = ModalFrequency(form, p, a);
  if (form.second_order()) {
    const double w = p[kNaturalFrequency];
    const double g = p[kAlpha] - 2.0 * p[kDelta] * omega * omega;
    damping -= 3.0 * p[kMu2] * g * a * a * a / (5.0 * kPi * (9.0 * omega * omega - w * w));
  }
  // 1 + delta a^2 / 2 = mass / 4 (exactly: scaling by 1/4 rounds alike).
  return damping / ((0.25 * o.mass) * omega);
}

ModalProperties ComputeModalProperties(ModelForm form, const ParameterVector& parameters,
                                       const ParameterMatrix* covariance, double a_min,
                                       double a_max, int points) {
  ModalProperties modal;
  if (!(a_min > 0.0) || !(a_max >= a_min) || points < 2) {
    modal.why = "no measured amplitude range";
    return modal;
  }
  modal.bands = covariance != nullptr;
  for (int i = 0; i < points; ++i) {
    ModalPoint point;
    point.a = a_min + (a_max - a_min) * i / (points - 1);
    const auto omega_hz = [&point, form](const ParameterVector& p) {
      return RadPerSecondToHz(ModalFrequency(form, p, point.a));
    };
    const auto zeta = [&point, form](const ParameterVector& p) {
      return ModalDampingRatio(form, p, point.a);
    };
    point.omega_hz = point.omega_hz_low = point.omega_hz_high = omega_hz(parameters);
    point.zeta = point.zeta_low = point.zeta_high = zeta(parameters);
    if (covariance != nullptr) {
      Band(parameters, *covariance, omega_hz, point.omega_hz, &point.omega_hz_low,
           &point.omega_hz_high);
      Band(parameters, *covariance, zeta, point.zeta, &point.zeta_low, &point.zeta_high);
    }
    modal.points.push_back(point);
  }
  return modal;
}

std::string ModalPropertiesCsv(const ModalProperties& modal) {
  std::string csv = "a,omega_hz,omega_hz_low,omega_hz_high,zeta,zeta_low,zeta_high\n";
  for (const ModalPoint& p : modal.points) {
    csv += StringPrintf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", p.a, p.omega_hz,
                        p.omega_hz_low, p.omega_hz_high, p.zeta, p.zeta_low, p.zeta_high);
  }
  return csv;
}

}  // namespace dwellfit
