// Harmonic-balance identification from the traces' Fourier coefficients
// (section 3.2.2, eqs. 3.12-3.13; Yasuda, Kamiya and Komakine 1997).
//
// With u(t) = Re sum_n U_n exp(i n Omega t) and a_b(t) likewise from A_n
// (trace_processing.h), every term of the equation of motion (docs/model.md)
//   u'' + w^2 u + delta (u u'^2 + u^2 u'') + alpha u^3 + 2 mu1 u'
//       + (mu2/Omega) u'|u'| = 2 eta_e a_b(t)
// is known at M points of one period. Its Fourier coefficients (Eigen's FFT
// of those M values) give, for harmonics n = 0..N, the balance
//   w^2 C_n[u] + delta C_n[u u'^2 + u^2 u''] + alpha C_n[u^3] + mu1 C_n[2u']
//     + mu2 C_n[u'|u'|/Omega] - eta_e C_n[2 a_b] = -C_n[u'']
// (cos and sin parts: two rows per n >= 1, one for n = 0), linear in
// theta = (w^2, delta, alpha, mu1, mu2, eta_e). The rows of all dwells are
// stacked, each dwell's divided by Omega^2 |U_1| (a relative error in u weighs
// alike at every dwell) and harmonic n's by n^2 (noise in u enters mostly
// through u'' ~ n^2 Omega^2 U_n), and solved by column-scaled least squares
// (Eigen's column-pivoting QR); standard errors from the residual variance
// and (J^T J)^-1, w's by the delta method.
#ifndef DWELLFIT_ESTIMATOR_TRACES_HARMONIC_BALANCE_H_
#define DWELLFIT_ESTIMATOR_TRACES_HARMONIC_BALANCE_H_

#include <ostream>
#include <vector>

#include "dwellfit/estimator/traces/trace_processing.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

struct HarmonicBalanceResult {
  ParameterVector estimate{};        // ParameterIndex layout, w in rad/s
  ParameterVector standard_error{};  // same layout
  int dwells = 0;
  int rows = 0;
  double rms_residual = 0.0;  // of the weighted rows
  // alpha - (2/3) delta Omega_ref^2 at `reference_rad_s` (docs/model.md).
  double effective_nonlinearity = 0.0;
  double effective_nonlinearity_error = 0.0;
  double reference_rad_s = 0.0;
};

// Fits the six parameters to `dwells` with `harmonics` harmonics (each dwell
// must carry at least that many). `reference_rad_s` <= 0: the identified w.
// Throws InputError when there are too few rows or dwells, the columns are
// rank deficient (e.g. one drive frequency only), or w^2 comes out <= 0.
HarmonicBalanceResult IdentifyHarmonicBalance(const std::vector<DwellHarmonics>& dwells,
                                              int harmonics, double reference_rad_s);

// The result as YAML (estimates, standard errors, effective nonlinearity).
void WriteHarmonicBalanceYaml(const HarmonicBalanceResult& result, std::ostream* out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_TRACES_HARMONIC_BALANCE_H_
