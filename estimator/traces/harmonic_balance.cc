#include "dwellfit/estimator/traces/harmonic_balance.h"

#include <cmath>
#include <complex>

#include "Eigen/Dense"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "unsupported/Eigen/FFT"

namespace dwellfit {
namespace {

using Complex = std::complex<double>;
constexpr int kUnknowns = 6;  // w^2, delta, alpha, mu1, mu2, eta_e
enum Column { kW2, kDeltaColumn, kAlphaColumn, kMu1Column, kMu2Column, kEtaColumn };

// Re sum_n c_n (i n Omega)^order exp(i n theta_j) at M points of one period.
std::vector<double> Synthesize(const std::vector<Complex>& c, int harmonics, double omega,
                               int order, int points) {
  std::vector<double> values(points, 0.0);
  for (int n = 0; n <= harmonics; ++n) {
    const Complex factor = std::pow(Complex(0.0, n * omega), order) * c[n];
    for (int j = 0; j < points; ++j) {
      values[j] += (factor * std::polar(1.0, kTwoPi * n * j / points)).real();
    }
  }
  return values;
}

// Rows of one dwell: its terms' Fourier coefficients, weighted; written into
// `system` ([jacobian | rhs]) from `row`.
void AddDwellRows(const DwellHarmonics& dwell, int harmonics, int points, int row,
                  Eigen::MatrixXd* system) {
  const double omega = dwell.drive_frequency_rad_s;
  const std::vector<double> u = Synthesize(dwell.u, harmonics, omega, 0, points);
  const std::vector<double> v = Synthesize(dwell.u, harmonics, omega, 1, points);
  const std::vector<double> acc = Synthesize(dwell.u, harmonics, omega, 2, points);
  const std::vector<double> base = Synthesize(dwell.base, harmonics, omega, 0, points);
  std::vector<std::vector<double>> terms(kUnknowns + 1, std::vector<double>(points));
  for (int j = 0; j < points; ++j) {
    terms[kW2][j] = u[j];
    terms[kDeltaColumn][j] = u[j] * v[j] * v[j] + u[j] * u[j] * acc[j];
    terms[kAlphaColumn][j] = u[j] * u[j] * u[j];
    terms[kMu1Column][j] = 2.0 * v[j];
    terms[kMu2Column][j] = v[j] * std::abs(v[j]) / omega;
    terms[kEtaColumn][j] = -2.0 * base[j];
    terms[kUnknowns][j] = -acc[j];
  }
  const double weight = 1.0 / (omega * omega * std::abs(dwell.u[1]));
  Eigen::FFT<double> fft;
  for (int t = 0; t <= kUnknowns; ++t) {
    std::vector<Complex> spectrum;
    fft.fwd(spectrum, terms[t]);
    for (int n = 0, r = row; n <= harmonics; ++n) {
      // Noise in u enters most through u'' ~ n^2: harmonic n weighs 1/n^2.
      const double harmonic_weight = n <= 1 ? 1.0 : 1.0 / (n * n);
      const Complex c =
          harmonic_weight * spectrum[n] * (n == 0 ? 1.0 : 2.0) / static_cast<double>(points);
      (*system)(r++, t) = weight * c.real();
      if (n > 0) (*system)(r++, t) = weight * c.imag();
    }
  }
}

}  // namespace

HarmonicBalanceResult IdentifyHarmonicBalance(const std::vector<DwellHarmonics>& dwells,
                                              int harmonics, double reference_rad_s) {
  if (harmonics < 1) throw InputError("harmonic balance: give at least one harmonic");
  const int rows_per_dwell = 2 * harmonics + 1;
  const int rows = rows_per_dwell * static_cast<int>(dwells.size());
  if (dwells.size() < 3 || rows < 2 * kUnknowns) {
    throw InputError(
        StringPrintf("harmonic balance: %zu dwell(s) give %d equations for %d "
                     "parameters; use more dwells",
                     dwells.size(), rows, kUnknowns));
  }
  int points = 64;
  while (points < 8 * (harmonics + 1)) points *= 2;
  Eigen::MatrixXd system(rows, kUnknowns + 1);
  for (std::size_t d = 0; d < dwells.size(); ++d) {
    if (static_cast<int>(dwells[d].u.size()) <= harmonics ||
        static_cast<int>(dwells[d].base.size()) <= harmonics || !(std::abs(dwells[d].u[1]) > 0)) {
      throw InputError(
          StringPrintf("harmonic balance: dwell %zu carries fewer than %d harmonics "
                       "or no response",
                       d, harmonics));
    }
    AddDwellRows(dwells[d], harmonics, points, static_cast<int>(d) * rows_per_dwell, &system);
  }
  const Eigen::MatrixXd jacobian = system.leftCols(kUnknowns);
  const Eigen::VectorXd rhs = system.col(kUnknowns);
  const Eigen::VectorXd scale = jacobian.colwise().norm().cwiseInverse().transpose();
  const Eigen::MatrixXd scaled = jacobian * scale.asDiagonal();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled);
  if (qr.rank() < kUnknowns) {
    throw InputError("harmonic balance: the dwells cannot separate the six parameters (rank " +
                     std::to_string(qr.rank()) + "); use several drive frequencies and levels");
  }
  const Eigen::VectorXd theta = scale.asDiagonal() * qr.solve(rhs);
  const Eigen::VectorXd residual = jacobian * theta - rhs;
  const double variance = residual.squaredNorm() / std::max(1, rows - kUnknowns);
  const Eigen::MatrixXd inverse = (scaled.transpose() * scaled).inverse();
  const Eigen::VectorXd se =
      scale.cwiseProduct(inverse.diagonal().cwiseSqrt()) * std::sqrt(variance);
  if (!(theta(kW2) > 0.0)) {
    throw InputError(
        StringPrintf("harmonic balance: w^2 came out %g <= 0; the data do not "
                     "show a resonance",
                     theta(kW2)));
  }
  HarmonicBalanceResult result;
  result.dwells = static_cast<int>(dwells.size());
  result.rows = rows;
  result.rms_residual = std::sqrt(residual.squaredNorm() / rows);
  const double w = std::sqrt(theta(kW2));
  const int columns[] = {kEtaColumn, kMu1Column, kMu2Column, kDeltaColumn, kAlphaColumn};
  const ParameterIndex indices[] = {kEtaE, kMu1, kMu2, kDelta, kAlpha};
  for (int i = 0; i < 5; ++i) {
    result.estimate[indices[i]] = theta(columns[i]);
    result.standard_error[indices[i]] = se(columns[i]);
  }
  result.estimate[kNaturalFrequency] = w;
  result.standard_error[kNaturalFrequency] = se(kW2) / (2.0 * w);
  result.reference_rad_s = reference_rad_s > 0.0 ? reference_rad_s : w;
  const double factor = 2.0 / 3.0 * result.reference_rad_s * result.reference_rad_s;
  result.effective_nonlinearity = theta(kAlphaColumn) - factor * theta(kDeltaColumn);
  // Delta method: the gradient of alpha - factor delta in the scaled columns.
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(kUnknowns);
  gradient(kAlphaColumn) = scale(kAlphaColumn);
  gradient(kDeltaColumn) = -factor * scale(kDeltaColumn);
  const double var_eff = variance * gradient.dot(inverse * gradient);
  result.effective_nonlinearity_error = std::sqrt(std::max(0.0, var_eff));
  return result;
}

void WriteHarmonicBalanceYaml(const HarmonicBalanceResult& result, std::ostream* out) {
  *out << "method: harmonic_balance\n"
       << StringPrintf("dwells: %d\nequations: %d\nrms_weighted_residual: %.6g\n", result.dwells,
                       result.rows, result.rms_residual)
       << "estimates:\n";
  for (int i = 0; i < kNumParameters; ++i) {
    const bool hz = i == kNaturalFrequency;
    const double value = hz ? RadPerSecondToHz(result.estimate[i]) : result.estimate[i];
    const double error = hz ? RadPerSecondToHz(result.standard_error[i]) : result.standard_error[i];
    *out << StringPrintf("  %s: {value: %.10g, standard_error: %.4g}\n",
                         hz ? "omega_hz" : ParameterName(i), value, error);
  }
  *out << StringPrintf(
      "effective_nonlinearity:\n  reference_hz: %.10g\n  value: %.10g\n  standard_error: %.4g\n",
      RadPerSecondToHz(result.reference_rad_s), result.effective_nonlinearity,
      result.effective_nonlinearity_error);
}

}  // namespace dwellfit
