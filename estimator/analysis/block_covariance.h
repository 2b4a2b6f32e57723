// The covariance of the entries of a FitDescription's blocks
// (estimator/fit/fit_description.h) at their current values, after a staged
// solve: from the local linearisation of the vertical-error fit, on the
// scaled problem. EstimateUncertainty (parameter_uncertainty.h) is its
// single-dataset case with the model's own diagnostics.
//
// With r_d(p) the dwell residuals of every dataset (vertical error,
// residuals/functors/vertical_error_residual.h; no penalties), n dwells, k
// free entries, and r_c(p) the caller's residual blocks
// (FitDescription::add_residuals: priors, each standardised so that one unit
// is one standard deviation), the Gauss-Newton covariance is
//
//   C = (J_d^T J_d / s^2 + J_c^T J_c)^-1,   J = dr/dp at the estimate,
//
// which without caller residual blocks is s^2 (J_d^T J_d)^-1. s^2 is the
// variance of one dwell residual: 1 when every dwell is divided by its point
// sigma, else 2 F_d / (n - k) with F_d = (1/2) sum r_d^2 (the reduced
// chi-square). C is in physical units with zero rows and columns for fixed
// entries. The 95 % interval of a free entry is p_j -/+ q se_j, se_j =
// sqrt(C_jj), q the 0.975 quantile of Student's t with n - k degrees of
// freedom (s estimated) or of the standard normal (s = 1).
//
// Scaling. The entries span nine decades (mu1 ~ 0.1, alpha ~ 1e9), so J is
// taken in tangent
// units of each entry's magnitude and its columns are normalised to unit
// length; the condition number of that matrix measures only how nearly the
// entries' effects on the residuals coincide (the collinearity diagnostic of
// Belsley, Kuh and Welsch). Above kMaxCollinearity no covariance is given
// (available = false) and the message names the entries the data cannot
// tell apart. Below it, ceres::Covariance (DENSE_SVD) inverts J^T J with the
// entries stepping in those normalised units (ScaledSubsetManifold), and
// returns C in physical units.
//
// Memory. J (n x k) is never held whole: its R factor is accumulated a chunk
// of residual blocks at a time (jacobian_factor.h), R^T R = J^T J, and the
// collinearity check and the null space are those of R with normalised
// columns, R_n. ceres::Covariance then runs on a small problem: one linear
// residual block r = M (x - x0) whose Jacobian in the normalised tangent
// coordinates is R_n, so that its (R_n^T R_n)^-1 is the (J_n^T J_n)^-1 of the
// whole problem.
//
// Blocks of the caller's own that its residual blocks read are held at their
// values: C is conditional on them.
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_BLOCK_COVARIANCE_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_BLOCK_COVARIANCE_H_

#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/identification_options.h"

namespace dwellfit {

// Largest sigma_max / sigma_min of the column-normalised Jacobian for which a
// covariance is reported: about 1/sqrt(machine epsilon), so that J^T J keeps a
// reciprocal condition number above ~1e-16 and its inverse is not rounding
// noise.
inline constexpr double kMaxCollinearity = 1e8;

struct BlockCovarianceOptions {
  // Rows of J evaluated and folded into R at a time: whole residual blocks
  // are added until the chunk has at least this many rows (>= 1). Memory
  // of order chunk_rows x k doubles; the result does not depend on it
  // beyond rounding.
  int chunk_rows = 4096;
  // False, with the reason in `error`, for a setting out of its range.
  bool IsValid(std::string* error) const;
};

struct BlockCovariance {
  // False: no covariance; `message` says why (invalid description or
  // options, nothing free, no degrees of freedom, the model cannot be
  // evaluated, entries the data cannot tell apart). Standard errors and covariance are then 0.
  bool available = false;
  std::string message;  // plain words, always set
  // Mixed point sigmas (some dwells standardised, some raw).
  std::vector<std::string> warnings;
  int num_points = 0;               // n: dwells of every dataset
  int num_free = 0;                 // k: free entries of the described blocks
  int degrees_of_freedom = 0;       // n - k
  int caller_residuals = 0;         // rows of the caller's residual blocks
  bool evaluated = false;           // the residuals and J were evaluated at the estimate
  bool all_standardised = false;    // every dwell divided by its point sigma (s = 1)
  bool some_standardised = false;   // some are
  double data_cost = 0.0;           // F_d
  double noise_sigma = 0.0;         // s
  double reduced_chi_square = 0.0;  // 2 F_d / (n - k)
  double interval_quantile = 0.0;   // q
  // sigma_max / sigma_min of the column-normalised J (0: not computed).
  double collinearity = 0.0;
  // Per ambient entry (FitDescription::AmbientIndex): value, standard error
  // (0 for fixed entries) and 95 % interval (the value for fixed entries);
  // empty when the description is invalid.
  std::vector<double> values, standard_error, ci95_low, ci95_high;
  Eigen::MatrixXd covariance;  // ambient x ambient, physical units
  std::vector<int> free;       // ambient index of each free entry, in order
  // When the data cannot tell entries apart: orthonormal null directions
  // (k x r) of the column-normalised J, J_n (every column of unit length).
  Eigen::MatrixXd null_space;
  // Once J is evaluated and no column vanishes: the cosines of the angles
  // between the columns of J_n, J_n^T J_n (k x k, symmetric, 1 on the
  // diagonal up to rounding): entry (i, j) is +-1 when free entries i and j
  // change the residuals along one direction. Computed as R_n^T R_n.
  Eigen::MatrixXd column_cosines;
  // The physical change per unit of each free entry's normalised coordinate.
  Eigen::VectorXd unit_scale;
};

// The covariance of every described entry at the blocks' current values,
// the dwells measured as `residual` says. Never throws or aborts.
BlockCovariance EstimateBlockCovariance(const FitDescription& fit, const ResidualOptions& residual,
                                        const BlockCovarianceOptions& options = {});

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_BLOCK_COVARIANCE_H_
