// How sure an identification is: 95 % intervals of the free parameters and
// of alpha_e, with the linearised standard errors and correlations beside
// them. docs/uncertainty.md has their measured coverage.
//
// Reported (IntervalMethod::kProfile): the profile of the cost the fit
// minimised, penalties included, at its last stage's weights
// (profile_likelihood.h). Linearised, kept beside it: with r(p) the data
// residuals (vertical error), J = dr/dp over the k free parameters at p^
// and n dwells,
//
//   C_d = s^2 (J^T J)^-1                                 ("gauss_newton")
//   C = s^2 H^-1,  H = J^T J + sum_k kappa_k g_k g_k^T   ("linearised_with_penalty")
//
// s^2 = 2 F(p^) / (n - k), F = (1/2) sum r_i^2; s = 1 when every residual is
// divided by its point's sigma (2 F / (n - k) is then the reduced
// chi-square). With the bifurcation-range penalty (eq. 3.17: (1/2) W u_k^n
// per enforced jump, u_k the fold's distance from its bracket's centre in
// half-widths) g_k = grad u_k and kappa_k = (1/2) W n (n - 1) u_k^(n - 2), the
// penalty's Gauss-Newton curvature. Interval p^_j -/+ q se_j, se_j =
// sqrt(C_jj), q the 0.975 quantile of Student's t with n - k degrees of
// freedom (s estimated) or of the normal (s = 1). alpha_e = alpha - (2/3)
// delta Omega_ref^2 has the variance g^T C g, g = [0, 0, 0, -(2/3) Omega_ref^2,
// 1, 0].
//
// (J^T J)^-1 comes from EstimateBlockCovariance (block_covariance.h), whose
// collinearity check (kMaxCollinearity) makes the covariance unavailable and
// names the parameters the sweeps cannot tell apart.
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_

#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/estimator/analysis/block_covariance.h"
#include "dwellfit/estimator/analysis/profile_likelihood.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// |correlation| above which a pair of free parameters is warned about.
inline constexpr double kCorrelationWarning = 0.99;

using ParameterMatrix = Eigen::Matrix<double, kNumParameters, kNumParameters>;

// How the intervals treat the bifurcation-range penalty (see above).
enum class IntervalMethod {
  kDataOnly,    // linearised, the dwells alone ("gauss_newton")
  kLinearised,  // linearised, with the penalty's curvature ("linearised_with_penalty")
  kProfile,     // profile likelihood of the fitted cost (the default)
};

// Width ratio of the linearised and the profile interval beyond which they disagree.
inline constexpr double kIntervalDisagreement = 1.5;
// See EstimateUncertaintyAtMinimum.
inline constexpr int kMaxRefits = 3;
inline constexpr double kReprofileShare = 0.05;
// Linearised half-widths below this share of every parameter's value mean
// data exact to round-off: the profile is not run.
inline constexpr double kRoundOffShare = 1e-9;

const char* IntervalMethodName(IntervalMethod method);  // "data_only", "linearised", "profile"
bool ParseIntervalMethod(const std::string& name, IntervalMethod* method);

struct ParameterUncertainty {
  // False: no covariance (errors, intervals and correlations 0); `message`
  // (always set) says why.
  bool available = false;
  std::string message;
  // "profile_likelihood", "gauss_newton" or "linearised_with_penalty".
  std::string interval_kind = "gauss_newton";
  ModelForm form;         // the member whose parameters these are (model_form.h)
  int penalty_terms = 0;  // enforced jumps whose curvature entered C
  // s, in the residual's unit (data length unit, or ln a for the relative
  // error); 1 when every residual is standardised by its point's sigma.
  double noise_sigma = 0.0;
  double reduced_chi_square = 0.0;   // 2 F / (n - k)
  int num_points = 0;                // n
  int num_free = 0;                  // k
  int degrees_of_freedom = 0;        // n - k
  bool noise_known = false;          // every dwell divided by its point sigma (s = 1)
  double interval_quantile = 0.0;    // q: t_{0.975, n-k}, or the normal's 1.95996
  ParameterVector standard_error{};  // 0 for fixed parameters
  // The reported 95 % intervals: the profile's (+/- infinity at an open end,
  // 0 at a bound), else the linearised ones, which are always kept beside.
  ParameterVector ci95_low{}, ci95_high{};
  ParameterVector linearised_ci95_low{}, linearised_ci95_high{};
  ProfileLikelihood profile;                              // behind profile-likelihood intervals
  ParameterMatrix covariance = ParameterMatrix::Zero();   // C, physical units
  ParameterMatrix correlation = ParameterMatrix::Zero();  // 1 on the free diagonal
  double collinearity = 0.0;                              // BlockCovariance::collinearity
  // alpha_e at the estimate, its standard error and 95 % intervals.
  double omega_ref_rad_s = 0.0;
  double effective_nonlinearity = 0.0;
  double effective_nonlinearity_standard_error = 0.0;
  double effective_nonlinearity_ci95_low = 0.0;
  double effective_nonlinearity_ci95_high = 0.0;
  double effective_nonlinearity_linearised_ci95_low = 0.0;
  double effective_nonlinearity_linearised_ci95_high = 0.0;
  // Fitted dwells past the end of their measured branch at the estimate: the
  // cost has a kink there and the linearisation is poor (coverage_study: 82 %
  // coverage of alpha_e with two or more such dwells, 94 % without).
  int dwells_past_branch_end = 0;
  std::vector<std::string> warnings;
};

// The uncertainty of the vertical-error fit of `fitted` at `estimate`
// (`omega_ref_rad_s` <= 0: the estimate's omega). Never throws: `available`
// and `message` say what went wrong. kProfile needs the fit's `summary` (its
// penalty weights; may be null without penalties).
ParameterUncertainty EstimateUncertainty(const std::vector<const Sweep*>& fitted,
                                         const IdentificationOptions& options,
                                         const ParameterVector& estimate, double omega_ref_rad_s,
                                         const FitSummary* summary = nullptr,
                                         IntervalMethod method = IntervalMethod::kProfile,
                                         int threads = 1);

// The profile-likelihood uncertainty of a finished fit at a minimum of its
// cost: where a profile finds a lower cost (kLowerCostTolerance), the last
// stage is solved again from there and profiled again (unless the cost fell
// by less than kReprofileShare of the threshold), up to kMaxRefits times;
// `result` then holds the new point and its message says so. A point still
// not a minimum becomes kNoConvergence, with the reason, and a warning.
ParameterUncertainty EstimateUncertaintyAtMinimum(const std::vector<const Sweep*>& fitted,
                                                  const IdentificationOptions& options,
                                                  double omega_ref_rad_s,
                                                  IdentificationResult* result, int threads = 1);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_
