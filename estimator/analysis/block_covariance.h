// The covariance of the entries of a FitDescription's blocks
// (estimator/fit/fit_description.h) at their current values, from the
// linearisation of the vertical-error fit. EstimateUncertainty
// (parameter_uncertainty.h) is its single-dataset case.
//
// With r_d(p) the dwell residuals of every dataset (no penalties), n dwells,
// k free entries, and r_c(p) the caller's residual blocks
// (FitDescription::add_residuals: priors, standardised to one standard
// deviation per unit), the Gauss-Newton covariance is
//
//   C = (J_d^T J_d / s^2 + J_c^T J_c)^-1,   J = dr/dp at the estimate,
//
// s^2 = 1 when every dwell is divided by its point sigma, else 2 F_d / (n - k)
// with F_d = (1/2) sum r_d^2. C is in physical units, zero for fixed entries.
// Interval p_j -/+ q se_j, q the 0.975 quantile of Student's t with n - k
// degrees of freedom (s estimated) or of the normal (s = 1).
//
// Scaling: the entries span nine decades (mu1 ~ 0.1, alpha ~ 1e9), so J is
// taken in tangent units of each entry's magnitude with unit-length columns,
// J_n; its condition number measures only how nearly the entries' effects
// coincide (Belsley, Kuh and Welsch's collinearity). Above kMaxCollinearity
// no covariance is given and the message names the entries concerned.
//
// Memory: J is never held whole; its R factor is accumulated a chunk of
// residual blocks at a time (jacobian_factor.h), and ceres::Covariance
// (DENSE_SVD) inverts R_n^T R_n = J_n^T J_n on a one-block problem.
// Blocks of the caller's that its residual blocks read are held: C is
// conditional on them.
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
// An entry's share of a (unit) null direction below which it is not implicated.
inline constexpr double kNullDirectionShare = 0.1;

struct BlockCovarianceOptions {
  // Rows of J folded into R at a time (whole residual blocks, >= 1); memory
  // ~ chunk_rows x k doubles, the result the same up to rounding.
  int chunk_rows = 4096;
  // False, with the reason in `error`, for a setting out of its range.
  bool IsValid(std::string* error) const;
};

struct BlockCovariance {
  bool available = false;             // false: no covariance (all 0); `message` says why
  std::string message;                // plain words, always set
  std::vector<std::string> warnings;  // mixed point sigmas (some dwells standardised)
  int num_points = 0;                 // n: dwells of every dataset
  int num_free = 0;                   // k: free entries of the described blocks
  int degrees_of_freedom = 0;         // n - k
  int caller_residuals = 0;           // rows of the caller's residual blocks
  bool evaluated = false;             // the residuals and J were evaluated at the estimate
  bool all_standardised = false;      // every dwell divided by its point sigma (s = 1)
  double data_cost = 0.0;             // F_d
  double noise_sigma = 0.0;           // s
  double reduced_chi_square = 0.0;    // 2 F_d / (n - k)
  double interval_quantile = 0.0;     // q
  double collinearity = 0.0;  // sigma_max / sigma_min of the column-normalised J (0: not computed)
  // Per ambient entry (FitDescription::AmbientIndex); fixed entries have
  // standard error 0 and interval [value, value]. Empty for an invalid
  // description.
  std::vector<double> values, standard_error, ci95_low, ci95_high;
  Eigen::MatrixXd covariance;      // ambient x ambient, physical units
  std::vector<int> free;           // ambient index of each free entry, in order
  Eigen::MatrixXd null_space;      // entries not told apart: J_n's null directions (k x r)
  Eigen::MatrixXd column_cosines;  // J_n^T J_n (k x k): cosines between J_n's columns
  Eigen::VectorXd unit_scale;      // physical change per unit of each free normalised coordinate
};

// q of two-sided intervals p -/+ q se at `confidence` (0.95: the 0.975
// quantile): Student's t with `degrees_of_freedom` (n - k, s estimated) or the
// normal (s known). `degrees_of_freedom` >= 1 unless `noise_known`;
// 0 < confidence < 1.
double IntervalQuantile(bool noise_known, int degrees_of_freedom, double confidence = 0.95);

// q of simultaneous intervals for `count` (>= 1) quantities: each at
// confidence^(1/count) (Sidak), so that all `count` hold together with
// probability at least `confidence` for jointly normal estimates, whatever
// their correlation (Sidak's inequality; equality when independent). With
// s estimated each is Student's t at that level.
double SimultaneousIntervalQuantile(bool noise_known, int degrees_of_freedom, int count,
                                    double confidence = 0.95);

// Standard errors sqrt(C_jj) and intervals value -/+ q se of the free
// entries from `covariance` and `interval_quantile`; fixed entries [value, value].
void IntervalsFromCovariance(BlockCovariance* c);

// The covariance of every described entry at the blocks' current values.
// Never throws or aborts.
BlockCovariance EstimateBlockCovariance(const FitDescription& fit, const ResidualOptions& residual,
                                        const BlockCovarianceOptions& options = {});

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_BLOCK_COVARIANCE_H_
