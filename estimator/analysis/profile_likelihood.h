// Profile-likelihood intervals of the fitted cost.
//
// With F(p) the cost the fit minimised (the dwells' vertical error,
// (1/2) sum r_i^2, plus the penalties of its last stage at the weights that
// stage used, FitSummary's StageSummary::penalties) and F^ = F(p^) its
// minimum, the profile of a quantity theta (one free parameter, or the
// effective nonlinearity alpha_e = alpha - (2/3) delta Omega_ref^2) is
//
//   F_theta(t) = min { F(p) : theta(p) = t, bounds kept },
//
// and its 95 % interval is the set where the profile rises at most
//
//   Delta = q^2 s^2 / 2
//
// above F^, q the interval quantile (Student's t with n - k degrees of
// freedom when the noise s is estimated, 2 F_data / (n - k) = s^2; the
// normal's 1.96 with point sigmas, s = 1). For a model linear in its
// parameters this is exactly the Gauss-Newton interval p^ -/+ q se; on a
// nonlinear model, near a bound or with the penalties' flat-bottomed walls
// (eq. 3.17), it follows the cost itself: asymmetric, never past a bound
// (eta_e, mu1, mu2 >= 0, w > 0), and as wide as the data (and the enforced
// jumps) allow, where the linearisation can be far too wide or too narrow.
//
// Each end is found by a search along one side: constrained fits at trial
// values t, each warm-started from the nearest fit inside the interval moved
// along the profile's path (the linearised path p^ + (t - theta^) C g /
// (g^T C g) from the estimate, C the linearised covariance and g the
// gradient of theta; then the secant through the last two fits inside), the
// first trial at the linearised interval's end, the
// next trial from the signed root z(t) = sqrt(F_theta(t) - F^), which is
// linear in t for a quadratic cost (secant from the estimate, then
// false position between the last trial inside and the first outside). An
// end is "crossed" when z is within kProfileTolerance of sqrt(Delta), "bound"
// when the quantity's bound is reached with the profile still below the
// threshold, and "open" when the search ends without crossing (the data do
// not bound the quantity there: the end is reported as +/- infinity).
//
// Beside the two searches, each quantity gets one constrained fit at the
// estimate's own value (held where it is, the others refitted). A
// constrained fit that ends below F^ (by more than kLowerCostTolerance,
// relative) shows that the estimate is no minimum: the lowest such point is
// returned, and the caller fits again from it (EstimateUncertaintyAtMinimum,
// parameter_uncertainty.h).
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_PROFILE_LIKELIHOOD_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_PROFILE_LIKELIHOOD_H_

#include <array>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// |z / sqrt(Delta) - 1| at which a trial ends the search of its side: the
// rise of the cost within 10 % of Delta; the end is then interpolated.
inline constexpr double kProfileTolerance = 0.05;
// A constrained fit whose cost is below F^ by more than this share of F^
// shows a lower point than the estimate.
inline constexpr double kLowerCostTolerance = 1e-7;
// Constrained fits per side at the most.
inline constexpr int kMaxProfileFitsPerSide = 14;

// The cost a profile minimises: the fit's last stage, as it was solved.
struct ProfileProblem {
  std::vector<const Sweep*> fitted;
  std::array<bool, kNumParameters> fixed{};
  ResidualOptions residual;
  // The last stage's penalties with the weights it used (in the cost's own
  // units, StageSummary::penalties): not weighed again.
  PenaltyOptions penalties;
  SolverSettings solver;
  double omega_ref_rad_s = 0.0;  // Omega_ref of alpha_e
  double threshold = 0.0;        // Delta, in the cost's units
  int threads = 1;               // profiles run side by side on these
};

// How one end of a profile interval was found.
enum class ProfileEnd {
  kCrossed,  // the profile crossed F^ + Delta there
  kBound,    // the quantity's bound (0), the profile still below the threshold
  kOpen,     // not crossed within the search: the data do not bound it
};
const char* ProfileEndName(ProfileEnd end);  // "crossed", "bound", "open"

struct ProfileInterval {
  bool computed = false;         // false: fixed, or not profiled
  double low = 0.0, high = 0.0;  // +/- infinity at an open end
  ProfileEnd low_end = ProfileEnd::kCrossed;
  ProfileEnd high_end = ProfileEnd::kCrossed;
  int fits = 0;  // constrained fits over both sides
};

struct ProfileLikelihood {
  double minimum_cost = 0.0;  // F^, evaluated on the profile's own problem
  double threshold = 0.0;     // Delta
  std::array<ProfileInterval, kNumParameters> parameters{};
  ProfileInterval effective_nonlinearity;  // alpha_e at omega_ref_rad_s
  // A constrained fit ended below F^ (kLowerCostTolerance): the lowest one.
  bool found_lower = false;
  double lower_cost = 0.0;
  ParameterVector lower_point{};
  std::string lower_while;  // "profiling mu1 at 1.42"
  int fits = 0;             // every constrained fit
};

// Minimises the profile problem's cost over its free parameters from `p`
// (updated), with nothing held but the fixed ones: a fit of the last stage
// again, with its weights. Returns the final cost (infinity when the cost
// cannot be evaluated).
double RefitProfileProblem(const ProfileProblem& problem, ParameterVector* p);

// The profile intervals of every free parameter and of alpha_e around
// `estimate` (a minimum of the problem's cost), from the linearised
// covariance `covariance` (6 x 6, physical units, zero for fixed
// parameters) and its interval quantile: the first trial is the
// linearised interval's end (a tenth of the value's magnitude where that
// is not finite or positive), warm-started on the linearised path.
ProfileLikelihood ProfileCost(const ProfileProblem& problem, const ParameterVector& estimate,
                              const Eigen::MatrixXd& covariance, double quantile);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_PROFILE_LIKELIHOOD_H_
