// How sure an identification is: standard errors, 95 % intervals and
// correlations of the parameters, from the local linearisation of the
// vertical-error fit at its estimate, with the bifurcation-range penalty's
// curvature and pull when the fit had it. docs/uncertainty.md has the
// measured coverage of both kinds of interval.
//
// With r(p) the data residuals (vertical error, residuals/functors/vertical_error_residual.h),
// J = dr/dp over the k free parameters at the estimate p^ and n dwell points,
// the Gauss-Newton covariance of the least-squares estimate is
//
//   C_d = s^2 (J^T J)^-1                                 (interval kind "gauss_newton")
//
// where s^2 is the variance of one residual:
//   - the residuals carry no per-point sigma: s^2 = 2 F(p^) / (n - k), with
//     F = (1/2) sum r_i^2 the final cost and n - k the degrees of freedom;
//   - every residual is divided by its point's sigma: the residuals are
//     already standardised, s = 1, and 2 F / (n - k) is reported as the
//     reduced chi-square (about 1 when model and sigmas are right).
//
// With the bifurcation-range penalty (interval kind
// "gauss_newton_sandwich_with_penalty"). The fit minimised F + sum_k (1/2) W
// u_k^n (eq. 3.17; u_k the enforced fold's distance from its bracket's centre
// in half-widths, n = 10, W the configured weight times the stage's
// penalty_unit, read from the fit's FitSummary). The penalty is no
// measurement with a noise of its own but a flat-bottomed wall: its
// Gauss-Newton curvature 25 W u^8 (du/dp)^2 is ~0 at the bracket's centre and
// huge at its edges, and leaving it out ignores what it pins (the dwells-alone
// intervals were up to 1.6 times the spread of the estimates). The estimate
// solves J^T r + grad P = 0, so a perturbation e of the data moves it by
// -H^-1 J^T e with H = J^T J + sum_k kappa_k g_k g_k^T, g_k = grad u_k,
// kappa_k = (1/2) W n (n - 1) u_k^(n - 2) (the term in u's second derivative
// is dropped), and
//
//   C = S + beta b b^T,   S = s^2 H^-1 J^T J H^-1,   b = (J^T J)^-1 grad P,
//
// the sandwich plus the penalty's pull b (how far it moved the estimate from
// the dwells' own minimum) as a bias term: a mean-squared-error interval,
// since the penalty draws the folds towards their brackets' centres. b is
// estimated at the estimate, so only the share beta of b b^T that stands out
// of b's own variance V = (C_d I_p) S (C_d I_p)^T counts (along b, in the
// metric of S: beta = max(0, 1 - b^T S^-1 V S^-1 b / (b^T S^-1 b)^2)).
// Computed as S = C_A - C_A I_p C_A with C_A = s^2 H^-1 from the one covariance
// path (one row sqrt(kappa_k) g_k / s per enforced jump) and I_p = sum_k
// kappa_k g_k g_k^T / s^2.
//
// Violated branch labels (label_pulls). A measured jump says that the dwell
// just before it lies on the branch that ends there. When the estimate ends
// that branch before the dwell (RootStatus::kBranchEnd), the fit has stopped
// at a kink of its cost where the fold crossed the dwell, short of where the
// labels put it: such fits are biased (thesis case without the penalty: 65 %
// of the fits, alpha_e covered in 90 % of all fits by C_d alone). For each
// such jump (except those the penalty holds, whose pull is counted above) the
// smallest move that puts the fold back on that dwell, in the metric of C,
//
//   delta = C g (u_dwell - u) / (g^T C g),   u, g as above for that jump,
//
// is added as a bias term delta delta^T: the intervals then reach back to
// where the labels are satisfied. IntervalMethod::kDataOnly gives C_d
// regardless (what identify reported before; for comparison).
//
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
// parameter on its bound 0 keeps a symmetric interval (warned); fitted dwells
// past the end of a branch without a measured jump get no label pull (the
// warning about dwells past their branch end stays); an
// enforced fold outside its bracket is warned, a missing one leaves its term
// out (warned); the penalty on without the fit's summary gives C_d (warned:
// too wide); the branch-stability penalty (eq. 3.19) is not in C.
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_

#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/estimator/analysis/block_covariance.h"
#include "dwellfit/estimator/data/sweep.h"
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
  kDataOnly,         // the dwells alone ("gauss_newton")
  kPenaltySandwich,  // the penalty's curvature in the sandwich (the default)
};

// "data_only", "penalty_sandwich".
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
  // Which kind of interval: "gauss_newton" (the dwells' linearisation alone)
  // or "gauss_newton_sandwich_with_penalty" (penalty_terms > 0); either may
  // be widened by label pulls (label_pulls > 0, said in `message`).
  std::string interval_kind = "gauss_newton";
  // Enforced jumps whose penalty curvature entered the sandwich.
  int penalty_terms = 0;
  // Measured jumps whose branch label the estimate violates (the fit stopped
  // at a kink) and whose move back widened the intervals.
  int label_pulls = 0;
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
ParameterUncertainty EstimateUncertainty(const std::vector<const Sweep*>& fitted,
                                         const IdentificationOptions& options,
                                         const ParameterVector& estimate, double omega_ref_rad_s,
                                         const FitSummary* summary = nullptr,
                                         IntervalMethod method = IntervalMethod::kPenaltySandwich);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_PARAMETER_UNCERTAINTY_H_
