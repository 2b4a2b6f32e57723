// How sure an identification is: standard errors, 95 % intervals and
// correlations of the parameters, from the local linearisation of the
// vertical-error fit at its estimate.
//
// With r(p) the data residuals (vertical error, residuals/functors/vertical_error_residual.h;
// no penalties), J = dr/dp over the k free parameters at the estimate p^ and
// n dwell points, the Gauss-Newton covariance of the least-squares estimate is
//
//   C = s^2 (J^T J)^-1
//
// where s^2 is the variance of one residual:
//   - the residuals carry no per-point sigma: s^2 = 2 F(p^) / (n - k), with
//     F = (1/2) sum r_i^2 the final cost and n - k the degrees of freedom;
//   - every residual is divided by its point's sigma: the residuals are
//     already standardised, s = 1, and 2 F / (n - k) is reported as the
//     reduced chi-square (about 1 when model and sigmas are right).
// C is in physical units (omega in rad/s) with zero rows and columns for fixed
// parameters. The 95 % interval of a free parameter is p^_j -/+ q se_j with
// se_j = sqrt(C_jj) and q the 0.975 quantile of Student's t with n - k degrees
// of freedom (s estimated) or of the standard normal (s = 1).
//
// The effective nonlinearity alpha_e = alpha - (2/3) delta Omega_ref^2 at the
// fixed reference Omega_ref has, by the delta method, the variance g^T C g
// with g = d alpha_e / dp = [0, 0, 0, -(2/3) Omega_ref^2, 1, 0].
//
// Identifiability. (J^T J)^-1 is computed by EstimateBlockCovariance
// (block_covariance.h), the one covariance path: ceres::Covariance (DENSE_SVD)
// on J with unit-length columns, so that its condition number measures only how
// nearly the parameters' effects on the fitted amplitudes coincide (the
// collinearity diagnostic of Belsley, Kuh and Welsch), not their units. When
// it exceeds kMaxCollinearity the covariance is not reported (available =
// false) and the message names the parameters the sweeps cannot tell apart.
// Below that, a correlation beyond kCorrelationWarning between two free
// parameters gives a warning; the intervals are still reported, and a
// well-determined combination (alpha_e when delta and alpha correlate) keeps
// its correct standard error.
//
// Limits. These are the intervals of the linearised, unbounded problem: a
// parameter on its bound 0 keeps a symmetric interval (warned), and near a
// fold the vertical error is only piecewise smooth (dwells_past_branch_end).
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_

#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/estimator/analysis/block_covariance.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// |correlation| above which a pair of free parameters is reported as weakly
// separated.
inline constexpr double kCorrelationWarning = 0.99;

using ParameterMatrix = Eigen::Matrix<double, kNumParameters, kNumParameters>;

struct ParameterUncertainty {
  // False: no covariance (every parameter fixed, no degrees of freedom, the
  // residuals cannot be evaluated, or the sweeps cannot tell some parameters
  // apart); `message` says which. Standard errors, intervals, covariance and
  // correlation are then 0 (never NaN).
  bool available = false;
  // Plain words for a person, always set.
  std::string message;
  // s: the residual standard deviation, in the residual's unit (the data's
  // length unit for the absolute error, ln a for the relative one); 1 when
  // every residual is standardised by its point's sigma.
  double noise_sigma = 0.0;
  // 2 F / (n - k): s^2 when s is estimated; the goodness of fit (about 1)
  // when every point has a sigma.
  double reduced_chi_square = 0.0;
  int num_points = 0;                       // n
  int num_free = 0;                         // k
  int degrees_of_freedom = 0;               // n - k
  double interval_quantile = 0.0;           // q: t_{0.975, n-k}, or the normal's 1.95996
  ParameterVector standard_error{};         // 0 for fixed parameters
  ParameterVector ci95_low{}, ci95_high{};  // estimate -/+ q standard_error
  ParameterMatrix covariance = ParameterMatrix::Zero();   // physical units
  ParameterMatrix correlation = ParameterMatrix::Zero();  // 1 on free diagonal
  // sigma_max / sigma_min of the column-normalised Jacobian of the free
  // parameters (1: orthogonal effects; +inf: exactly collinear; 0 when not
  // computed).
  double collinearity = 0.0;
  // alpha - (2/3) delta omega_ref^2 at the estimate, its standard error and
  // 95 % interval.
  double omega_ref_rad_s = 0.0;
  double effective_nonlinearity = 0.0;
  double effective_nonlinearity_standard_error = 0.0;
  double effective_nonlinearity_ci95_low = 0.0;
  double effective_nonlinearity_ci95_high = 0.0;
  // Fitted dwells whose measured branch ends before their control value at
  // the estimate (the model's fold falls short of them). The cost has a kink
  // there and the linearisation is poor: over 600 noisy replicas of the
  // thesis case, alpha_e's interval covered the truth in 82 % of the fits
  // with two or more such dwells and in 94 % of the others (coverage_study).
  int dwells_past_branch_end = 0;
  // Weakly determined pairs, dwells past their branch end, parameters on a
  // bound, mixed point sigmas.
  std::vector<std::string> warnings;
};

// Linearises the vertical-error fit of `fitted` at `estimate` (residual error
// measure, point sigmas and fixed parameters from `options`; penalties and
// stages are ignored) and returns the parameters' uncertainty.
// `omega_ref_rad_s` <= 0 means the estimate's omega (as in
// MakeIdentificationReport). Never throws for degenerate data: `available`
// and `message` say what went wrong.
ParameterUncertainty EstimateUncertainty(const std::vector<const Sweep*>& fitted,
                                         const IdentificationOptions& options,
                                         const ParameterVector& estimate, double omega_ref_rad_s);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_
