// Profile-likelihood intervals of the fitted cost.
//
// With F(p) the cost the fit minimised (the dwells' vertical error plus the
// penalties of its last stage at the weights it used) and F^ = F(p^), the
// profile of a quantity theta (a free parameter, or alpha_e = alpha - (2/3)
// delta Omega_ref^2) is
//
//   F_theta(t) = min { F(p) : theta(p) = t, bounds kept },
//
// and its 95 % interval is where the profile rises at most Delta = q^2 s^2 / 2
// above F^ (q and s as for the linearised interval, parameter_uncertainty.h).
// For a model linear in its parameters this is the Gauss-Newton interval; on
// a nonlinear model, near a bound or at the penalties' flat-bottomed walls
// (eq. 3.17) it follows the cost: asymmetric and never past a bound.
//
// Each end is found along one side by constrained fits at trial values t,
// warm-started from the nearest fit inside moved along the profile's path
// (first the linearised path p^ + (t - theta^) C g / (g^T C g), g = grad
// theta; then the secant through the last two fits inside). The first trial
// is a share of the linearised half-width, the next ones come from the
// signed root z(t) = sqrt(F_theta(t) - F^), linear in t for a quadratic cost
// (secant, then false position). An end is "crossed" when z is within
// kProfileTolerance of sqrt(Delta), "bound" at the quantity's bound with the
// profile still below, and "open" when the search ends without crossing
// (reported as +/- infinity).
//
// Each quantity also gets one constrained fit at the estimate's own value. A
// constrained fit ending below F^ (kLowerCostTolerance) shows the estimate is
// no minimum: the lowest such point is returned for the caller to fit again
// from (EstimateUncertaintyAtMinimum).
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
  PenaltyOptions penalties;  // the last stage's, at the weights it used (StageSummary::penalties)
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

// Fits the last stage again from `p` (updated); returns the final cost
// (infinity when it cannot be evaluated).
double RefitProfileProblem(const ProfileProblem& problem, ParameterVector* p);

// The profile intervals of every free parameter and of alpha_e around
// `estimate`, from the linearised `covariance` (6 x 6, physical units) and
// its interval quantile (first step and path, see above).
ProfileLikelihood ProfileCost(const ProfileProblem& problem, const ParameterVector& estimate,
                              const Eigen::MatrixXd& covariance, double quantile);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_PROFILE_LIKELIHOOD_H_
