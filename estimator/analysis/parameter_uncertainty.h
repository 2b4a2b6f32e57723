// How sure an identification is: 95 % intervals of the free parameters and
// of alpha_e, with the linearised standard errors and correlations beside
// them. docs/uncertainty.md has their measured coverage.
//
// The reported intervals (IntervalMethod::kProfile, "profile_likelihood")
// are those of the profile of the cost the fit minimised, penalties
// included, at the weights its last stage used (profile_likelihood.h): the
// values a quantity can take while the cost rises at most q^2 s^2 / 2 above
// its minimum, the other free parameters refitted, the bounds kept.
//
// The linearised kind is kept beside them (linearised_ci95_*, and the
// reported kind where a profile cannot be run). With r(p) the data
// residuals (vertical error, residuals/functors/vertical_error_residual.h),
// J = dr/dp over the k free parameters at the estimate p^ and n dwells,
//
//   C_d = s^2 (J^T J)^-1                                 ("gauss_newton")
//
// where s^2 is the variance of one residual:
//   - the residuals carry no per-point sigma: s^2 = 2 F(p^) / (n - k), with
//     F = (1/2) sum r_i^2 the final cost and n - k the degrees of freedom;
//   - every residual is divided by its point's sigma: the residuals are
//     already standardised, s = 1, and 2 F / (n - k) is reported as the
//     reduced chi-square (about 1 when model and sigmas are right).
// With the bifurcation-range penalty (eq. 3.17: (1/2) W u_k^n per enforced
// jump, u_k the fold's distance from its bracket's centre in half-widths)
// the linearisation of the penalised cost ("linearised_with_penalty"):
//
//   C = s^2 H^-1,   H = J^T J + sum_k kappa_k g_k g_k^T,
//
// g_k = grad u_k, kappa_k = (1/2) W n (n - 1) u_k^(n - 2) the penalty's
// Gauss-Newton curvature; the quadratic approximation of the same profile.
// The 95 % interval is p^_j -/+ q se_j, se_j = sqrt(C_jj), q the 0.975
// quantile of Student's t with n - k degrees of freedom (s estimated) or of
// the standard normal (s = 1). alpha_e = alpha - (2/3) delta Omega_ref^2 has
// the variance g^T C g, g = [0, 0, 0, -(2/3) Omega_ref^2, 1, 0].
//
// Identifiability. (J^T J)^-1 is computed by EstimateBlockCovariance
// (block_covariance.h), the one covariance path: ceres::Covariance (DENSE_SVD)
// on J with unit-length columns, so that its condition number measures only how
// nearly the parameters' effects on the fitted amplitudes coincide (the
// collinearity diagnostic of Belsley, Kuh and Welsch), not their units. When
// it exceeds kMaxCollinearity the covariance is not reported (available =
// false) and the message names the parameters the sweeps cannot tell apart.
// Below that, a correlation beyond kCorrelationWarning between two free
// parameters gives a warning.
//
// Warnings: the linearised and the profile interval differing by more than
// kIntervalDisagreement in width; a profile end the data do not bound; an
// enforced fold outside its bracket or missing; fitted dwells past the end
// of their branch; a parameter on its bound.
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

// |correlation| above which a pair of free parameters is reported as weakly
// separated.
inline constexpr double kCorrelationWarning = 0.99;

using ParameterMatrix = Eigen::Matrix<double, kNumParameters, kNumParameters>;

// How the intervals treat the bifurcation-range penalty (see above).
enum class IntervalMethod {
  kDataOnly,    // linearised, the dwells alone ("gauss_newton")
  kLinearised,  // linearised, with the penalty's curvature ("linearised_with_penalty")
  kProfile,     // profile likelihood of the fitted cost (the default)
};

// |width ratio| beyond which the linearised and the profile interval of a
// quantity are said to disagree (a warning).
inline constexpr double kIntervalDisagreement = 1.5;
// Fits again from a lower point the profile found, at the most
// (EstimateUncertaintyAtMinimum).
inline constexpr int kMaxRefits = 3;
// A fit again from a lower point the profile found that lowers the cost by
// less than this share of the threshold keeps that profile's intervals;
// more, and the profiles run again from the new point.
inline constexpr double kReprofileShare = 0.05;
// Linearised half-widths below this share of every parameter's value mean
// data exact to round-off: the profile is not run.
inline constexpr double kRoundOffShare = 1e-9;

// "data_only", "linearised", "profile".
const char* IntervalMethodName(IntervalMethod method);
// False for an unknown name.
bool ParseIntervalMethod(const std::string& name, IntervalMethod* method);

struct ParameterUncertainty {
  // False: no covariance (every parameter fixed, no degrees of freedom, the
  // residuals cannot be evaluated, or the sweeps cannot tell some parameters
  // apart); `message` says which. Standard errors, intervals, covariance and
  // correlation are then 0 (never NaN).
  bool available = false;
  // Plain words for a person, always set.
  std::string message;
  // Notes that join the message (why a kind was not used).
  std::vector<std::string> message_notes;
  // "profile_likelihood", or a linearised kind: "gauss_newton" (the dwells
  // alone) or "linearised_with_penalty" (penalty_terms > 0).
  std::string interval_kind = "gauss_newton";
  // Enforced jumps whose penalty curvature entered the linearisation.
  int penalty_terms = 0;
  // s: the residual standard deviation, in the residual's unit (the data's
  // length unit for the absolute error, ln a for the relative one); 1 when
  // every residual is standardised by its point's sigma.
  double noise_sigma = 0.0;
  // 2 F / (n - k): s^2 when s is estimated; the goodness of fit (about 1)
  // when every point has a sigma.
  double reduced_chi_square = 0.0;
  int num_points = 0;                // n
  int num_free = 0;                  // k
  int degrees_of_freedom = 0;        // n - k
  double interval_quantile = 0.0;    // q: t_{0.975, n-k}, or the normal's 1.95996
  ParameterVector standard_error{};  // 0 for fixed parameters
  // The reported 95 % intervals: the profile's (interval_kind
  // "profile_likelihood"; +/- infinity at an open end, 0 at a bound), else
  // the linearised estimate -/+ q standard_error.
  ParameterVector ci95_low{}, ci95_high{};
  // The linearised intervals, estimate -/+ q standard_error, always.
  ParameterVector linearised_ci95_low{}, linearised_ci95_high{};
  // The profiles behind profile-likelihood intervals (ends, fits, a lower
  // point found).
  ProfileLikelihood profile;
  // Physical units; with the bias terms (penalty pull, label pulls) when
  // there are any, as the standard errors.
  ParameterMatrix covariance = ParameterMatrix::Zero();
  // 1 on the free diagonal; of the covariance without the bias terms (their
  // rank-one shares would make every pair look collinear).
  ParameterMatrix correlation = ParameterMatrix::Zero();
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
  double effective_nonlinearity_linearised_ci95_low = 0.0;
  double effective_nonlinearity_linearised_ci95_high = 0.0;
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
// measure, point sigmas, fixed parameters and the bifurcation-range penalty's
// enforced jumps from `options`; the stages are ignored), with the fold
// brackets `rule` names, and returns the parameters' uncertainty.
// `omega_ref_rad_s` <= 0 means the estimate's omega (as in
// MakeIdentificationReport). Never throws for degenerate data: `available`
// and `message` say what went wrong.
// kProfile needs the fit's `summary` (its last stage's penalty weights;
// without penalties it may be null) and runs the profiles on `threads`.
ParameterUncertainty EstimateUncertainty(const std::vector<const Sweep*>& fitted,
                                         const IdentificationOptions& options,
                                         const ParameterVector& estimate, double omega_ref_rad_s,
                                         const FitSummary* summary = nullptr,
                                         IntervalMethod method = IntervalMethod::kProfile,
                                         int threads = 1);

// The profile-likelihood uncertainty of a finished fit that is a minimum of
// its cost: where a profile finds a lower cost than the fit's (by more than
// kLowerCostTolerance), the fit's last stage is solved again from there
// (RefitProfileProblem) and profiled again (unless the cost fell by less
// than kReprofileShare of the threshold), up to kMaxRefits times;
// `result` then holds the new parameters and cost, and its message says so.
// A point still not a minimum after that is no longer "converged"
// (kNoConvergence, with the reason) and the uncertainty warns.
ParameterUncertainty EstimateUncertaintyAtMinimum(const std::vector<const Sweep*>& fitted,
                                                  const IdentificationOptions& options,
                                                  double omega_ref_rad_s,
                                                  IdentificationResult* result, int threads = 1);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_
