#include "dwellfit/estimator/analysis/profile_likelihood.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "ceres/manifold.h"
#include "ceres/solver.h"
#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/stage_problem.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "glog/logging.h"
#include "tbb/parallel_for.h"
#include "tbb/task_arena.h"

namespace dwellfit {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// The profiled quantity: a parameter (ParameterIndex), alpha_e, or none (a refit).
constexpr int kEffective = kNumParameters;
constexpr int kNone = -1;
// Share of the estimate at which the lower end of eta_e and w (positive) is
// tried; a profile still below the threshold there reaches the bound 0.
constexpr double kPositiveFloorShare = 1e-3;
// The first trial's share of the linearised half-width: where the
// linearisation is right the second trial (secant, 4x) lands on the end;
// where it is far too wide (a penalty's wall, a valley) the first fit stays
// in the estimate's basin.
constexpr double kFirstStepShare = 0.25;
// A profile's constrained fits end when an iteration lowers the cost by less
// than this share of Delta (or the solver's own tolerance, if looser): 1e-6
// relative on the measured beam, the ends well within kProfileTolerance at a
// third fewer iterations.
constexpr double kProfileCostShare = 1e-3;

// The block's free entries step in units of their scale (as
// ScaledSubsetManifold), and alpha moves with delta so that alpha_e =
// alpha - c delta, c = (2/3) Omega_ref^2, keeps its value:
//   Plus(x, d) = x + sum_k scale_k d_k e_{free_k} + c scale_delta d_delta e_alpha.
class TiedAlphaManifold : public ceres::Manifold {
 public:
  TiedAlphaManifold(const ParameterVector& scale, const std::array<bool, kNumParameters>& held,
                    double c)
      : scale_(scale), c_(c) {
    for (int i = 0; i < kNumParameters; ++i) {
      if (!held[i] && i != kAlpha) free_.push_back(i);
    }
  }
  int AmbientSize() const override { return kNumParameters; }
  int TangentSize() const override { return static_cast<int>(free_.size()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    std::copy(x, x + kNumParameters, x_plus_delta);
    for (size_t k = 0; k < free_.size(); ++k) {
      const double move = scale_[free_[k]] * delta[k];
      x_plus_delta[free_[k]] += move;
      if (free_[k] == kDelta) x_plus_delta[kAlpha] += c_ * move;
    }
    return true;
  }
  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    const int m = TangentSize();
    std::fill(jacobian, jacobian + kNumParameters * m, 0.0);
    for (int k = 0; k < m; ++k) {
      jacobian[free_[k] * m + k] = scale_[free_[k]];
      if (free_[k] == kDelta) jacobian[kAlpha * m + k] = c_ * scale_[kDelta];
    }
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    for (size_t k = 0; k < free_.size(); ++k) {
      y_minus_x[k] = (y[free_[k]] - x[free_[k]]) / scale_[free_[k]];
    }
    return true;
  }
  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    const int m = TangentSize();
    std::fill(jacobian, jacobian + kNumParameters * m, 0.0);
    for (int k = 0; k < m; ++k) jacobian[k * kNumParameters + free_[k]] = 1.0 / scale_[free_[k]];
    return true;
  }

 private:
  ParameterVector scale_;
  double c_;
  std::vector<int> free_;
};

double AlphaETie(const ProfileProblem& problem) {
  return (2.0 / 3.0) * problem.omega_ref_rad_s * problem.omega_ref_rad_s;
}

// Minimises the cost from `p` with `held` entries kept (alpha tied to delta
// when `tie`) to the looser of the solver's and `function_tolerance`.
// Returns the final cost, infinity when it cannot be evaluated.
double MinimiseHeld(const ProfileProblem& problem, const std::array<bool, kNumParameters>& held,
                    bool tie, double function_tolerance, ParameterVector* p) {
  const FitDescription fit = SingleBlockFit(problem.fitted, held, p, problem.residual.form);
  std::string error;
  if (!fit.IsValid(&error)) return kInfinity;
  StageSetup setup;
  setup.residuals.residual = ResidualKind::kVertical;
  setup.residuals.residual_options = problem.residual;
  ParameterVector scale;
  for (int i = 0; i < kNumParameters; ++i) scale[i] = (*p)[i] != 0.0 ? std::abs((*p)[i]) : 1.0;
  setup.scale.assign(scale.begin(), scale.end());
  setup.num_threads = 1;
  StageProblem stage(fit, setup);
  if (problem.penalties.bifurcation_range.enabled || problem.penalties.branch_stability.enabled) {
    stage.AddPenalties(problem.penalties);
  }
  stage.Configure();
  const bool any_free = std::count(held.begin(), held.end(), false) > (tie ? 1 : 0);
  if (!any_free) {
    const double cost = stage.DataCost() + stage.PenaltyCost();
    return std::isfinite(cost) ? cost : kInfinity;
  }
  if (tie)
    stage.problem()->SetManifold(p->data(), new TiedAlphaManifold(scale, held, AlphaETie(problem)));
  ceres::Solver::Options options = MakeSolverOptions(problem.solver);
  options.max_num_line_search_step_size_iterations = 0;  // as the vertical stage (staged_solve.cc)
  options.function_tolerance = std::max(options.function_tolerance, function_tolerance);
  ceres::Solver::Summary summary;
  ceres::Solve(options, stage.problem(), &summary);
  VLOG(2) << "profile fit: " << summary.BriefReport() << " in " << summary.total_time_in_seconds
          << " s";
  if (!summary.IsSolutionUsable() || !std::isfinite(summary.final_cost)) return kInfinity;
  return summary.final_cost;
}

// The constrained minimum with `quantity` held at `value`, from `p`; a
// profile's fit (any quantity) ends on kProfileCostShare of Delta, a refit
// (kNone) on the solver's own tolerance.
double ConstrainedMinimum(const ProfileProblem& problem, int quantity, double value,
                          double minimum_cost, ParameterVector* p) {
  std::array<bool, kNumParameters> held = problem.fixed;
  bool tie = false;
  if (quantity >= 0 && quantity < kNumParameters) {
    held[quantity] = true;
    (*p)[quantity] = value;
  } else if (quantity == kEffective) {
    const double c = AlphaETie(problem);
    if (!problem.fixed[kAlpha]) {
      (*p)[kAlpha] = value + c * (*p)[kDelta];
      held[kAlpha] = true;
      tie = !problem.fixed[kDelta];
    } else {
      (*p)[kDelta] = ((*p)[kAlpha] - value) / c;
      held[kDelta] = true;
    }
  }
  const double tolerance = quantity == kNone || !(minimum_cost > 0.0)
                               ? 0.0
                               : kProfileCostShare * problem.threshold / minimum_cost;
  return MinimiseHeld(problem, held, tie, tolerance, p);
}

double ValueOf(const ProfileProblem& problem, int quantity, const ParameterVector& p) {
  return quantity == kEffective
             ? EffectiveNonlinearity(problem.residual.form, p, problem.omega_ref_rad_s)
             : p[quantity];
}

bool IsProfiled(const ProfileProblem& problem, int quantity) {
  if (quantity == kEffective) {
    // A member without the inertia delta has alpha_e = alpha (profiled as alpha).
    return problem.residual.form.has_inertia() &&
           !(problem.fixed[kAlpha] && problem.fixed[kDelta]) && problem.omega_ref_rad_s > 0.0;
  }
  return !problem.fixed[quantity];
}

// The lowest value a trial may take on the lower side (-infinity: none);
// reaching it means the bound 0.
double LowerFloor(int quantity, double estimate) {
  if (quantity == kMu1 || quantity == kMu2) return 0.0;
  if (quantity == kEtaE || quantity == kNaturalFrequency) {
    return kPositiveFloorShare * std::abs(estimate);
  }
  return -kInfinity;
}

struct Trial {
  double t = 0.0;  // the quantity's value
  double z = 0.0;  // sqrt(F_theta(t) - F^), infinity where not evaluable
  ParameterVector p{};
};

struct SideResult {
  double end = 0.0;
  ProfileEnd kind = ProfileEnd::kOpen;
  int fits = 0;
  std::optional<Trial> lower;  // the lowest constrained fit below F^
  double lower_cost = kInfinity;

  // Keeps `trial` when its `cost` is the lowest below F^ so far.
  void NoteLower(const Trial& trial, double cost, double minimum_cost) {
    if (!(cost < minimum_cost * (1.0 - kLowerCostTolerance) && cost < lower_cost)) return;
    lower = trial;
    lower_cost = cost;
  }
  SideResult& End(double at, ProfileEnd how) {
    end = at;
    kind = how;
    return *this;
  }
};

// One side's search (see the header).
struct Side {
  int quantity = 0;
  double sign = 1.0;
  ParameterVector estimate{};
  ParameterVector path{};  // d p / d theta, linearised
  double first_step = 0.0;
};

// The next trial: secant from the estimate while none is outside (growth
// 1.5x to 4x), else false position in z between the last inside and the
// first outside (10 % inside the bracket), bisection where z is infinite.
double NextTrial(const Trial& centre, const Trial& inside, const std::optional<Trial>& outside,
                 const Side& side, double target) {
  if (!outside) {
    const double reached = std::abs(inside.t - centre.t);
    if (reached == 0.0) return centre.t + side.sign * side.first_step;
    const double growth = inside.z > 0.0 ? std::min(target / inside.z, 4.0) : 4.0;
    return centre.t + side.sign * reached * std::max(growth, 1.5);
  }
  if (!std::isfinite(outside->z)) return 0.5 * (inside.t + outside->t);
  const double share = std::clamp((target - inside.z) / (outside->z - inside.z), 0.1, 0.9);
  return inside.t + share * (outside->t - inside.t);
}

// The interval's end between the last trial inside and the first outside,
// linear in z.
double Interpolate(const Trial& inside, const Trial& outside, double target) {
  if (!std::isfinite(outside.z)) return inside.t;
  const double share = (target - inside.z) / (outside.z - inside.z);
  return inside.t + std::clamp(share, 0.0, 1.0) * (outside.t - inside.t);
}

// The warm start of a trial at `t`: the last fit inside moved along the
// path (see the header), inside the model's range.
ParameterVector WarmStart(const Trial& inside, const std::optional<Trial>& before, const Side& side,
                          double t) {
  ParameterVector p = inside.p;
  for (int i = 0; i < kNumParameters; ++i) {
    const double slope = before && before->t != inside.t
                             ? (inside.p[i] - before->p[i]) / (inside.t - before->t)
                             : side.path[i];
    if (std::isfinite(slope)) p[i] += slope * (t - inside.t);
    const bool positive = i == kEtaE || i == kNaturalFrequency;
    if (positive && !(p[i] > 0.0)) p[i] = kPositiveFloorShare * std::abs(side.estimate[i]);
    if ((i == kMu1 || i == kMu2) && !(p[i] >= 0.0)) p[i] = 0.0;
  }
  return p;
}

SideResult SearchSide(const ProfileProblem& problem, const Side& side, double minimum_cost) {
  const double target = std::sqrt(problem.threshold);
  const Trial centre{ValueOf(problem, side.quantity, side.estimate), 0.0, side.estimate};
  const double floor = side.sign < 0.0 && side.quantity != kEffective
                           ? LowerFloor(side.quantity, centre.t)
                           : -kInfinity;
  SideResult result;
  if (centre.t <= floor) return result.End(0.0, ProfileEnd::kBound);
  Trial inside = centre;
  std::optional<Trial> before, outside;
  while (result.fits < kMaxProfileFitsPerSide) {
    Trial trial;
    trial.t = NextTrial(centre, inside, outside, side, target);
    const bool at_floor = trial.t <= floor;
    if (at_floor) trial.t = floor;
    trial.p = WarmStart(inside, before, side, trial.t);
    double cost = ConstrainedMinimum(problem, side.quantity, trial.t, minimum_cost, &trial.p);
    ++result.fits;
    if (!(cost <= minimum_cost + problem.threshold)) {
      // Outside, or so it seems: the cost is rough (kinks where a fold
      // passes a dwell), and a fit from the last fit inside itself may end
      // lower than one from the extrapolated path.
      ParameterVector again = inside.p;
      const double retry =
          ConstrainedMinimum(problem, side.quantity, trial.t, minimum_cost, &again);
      ++result.fits;
      if (retry < cost) {
        cost = retry;
        trial.p = again;
      }
    }
    result.NoteLower(trial, cost, minimum_cost);
    trial.z = std::isfinite(cost) ? std::sqrt(std::max(cost - minimum_cost, 0.0)) : kInfinity;
    if (std::abs(trial.z / target - 1.0) <= kProfileTolerance) {
      return result.End(trial.t, ProfileEnd::kCrossed);
    }
    if (trial.z < target) {
      before = inside;
      inside = trial;
      if (at_floor) return result.End(0.0, ProfileEnd::kBound);
    } else {
      outside = trial;
    }
    if (outside && std::abs(outside->t - inside.t) <= 1e-9 * std::abs(centre.t)) break;
  }
  if (outside) return result.End(Interpolate(inside, *outside, target), ProfileEnd::kCrossed);
  return result.End(side.sign * kInfinity, ProfileEnd::kOpen);
}

// The constrained fit with the quantity held at the estimate's own value,
// from the estimate: only its lower point, if any, counts.
SideResult FitAtEstimate(const ProfileProblem& problem, int quantity,
                         const ParameterVector& estimate, double minimum_cost) {
  SideResult result;
  Trial trial{ValueOf(problem, quantity, estimate), 0.0, estimate};
  result.NoteLower(trial, ConstrainedMinimum(problem, quantity, trial.t, minimum_cost, &trial.p),
                   minimum_cost);
  result.fits = 1;
  return result;
}

// The side's linearised path d p / d theta = C g / (g^T C g) and first step
// q sqrt(g^T C g), g the gradient of the quantity.
Side MakeSide(const ProfileProblem& problem, int quantity, double sign,
              const ParameterVector& estimate, const Eigen::MatrixXd& covariance, double quantile) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(kNumParameters);
  if (quantity == kEffective) {
    g[kDelta] = -AlphaETie(problem);
    g[kAlpha] = 1.0;
  } else {
    g[quantity] = 1.0;
  }
  const bool usable = covariance.rows() == kNumParameters && covariance.cols() == kNumParameters;
  const Eigen::VectorXd cg = usable ? Eigen::VectorXd(covariance * g) : g;
  const double variance = usable ? g.dot(cg) : 0.0;
  Side side{quantity, sign, estimate, {}, 0.0};
  const double value = ValueOf(problem, quantity, estimate);
  side.first_step = kFirstStepShare * quantile * std::sqrt(std::max(variance, 0.0));
  if (!(side.first_step > 0.0) || !std::isfinite(side.first_step)) {
    side.first_step = value != 0.0 ? 0.1 * std::abs(value) : 1.0;
  }
  const bool along_covariance = variance > 0.0 && std::isfinite(variance);
  for (int i = 0; i < kNumParameters; ++i) {
    side.path[i] = along_covariance ? cg[i] / variance : (g[i] != 0.0 ? 1.0 / g[i] : 0.0);
  }
  return side;
}

}  // namespace

const char* ProfileEndName(ProfileEnd end) {
  constexpr const char* kNames[] = {"crossed", "bound", "open"};
  return NameOf(kNames, end);
}

double RefitProfileProblem(const ProfileProblem& problem, ParameterVector* p) {
  return ConstrainedMinimum(problem, kNone, 0.0, 0.0, p);
}

ProfileLikelihood ProfileCost(const ProfileProblem& problem, const ParameterVector& estimate,
                              const Eigen::MatrixXd& covariance, double quantile) {
  ProfileLikelihood profile;
  profile.threshold = problem.threshold;
  ParameterVector at_estimate = estimate;
  profile.minimum_cost =
      MinimiseHeld(problem, std::array<bool, kNumParameters>{true, true, true, true, true, true},
                   false, 0.0, &at_estimate);
  std::vector<int> quantities;
  for (int q = 0; q <= kEffective; ++q) {
    if (IsProfiled(problem, q)) quantities.push_back(q);
  }
  // Per quantity three searches (3 q + k): the lower side, the upper side,
  // and the fit at the estimate's own value (a lower cost there shows a fit
  // that stopped short along a valley, or a parameter on its bound whose
  // neighbours were not at their minimum).
  std::vector<SideResult> sides(3 * quantities.size());
  const auto search = [&](size_t i) {
    const int q = quantities[i / 3];
    if (i % 3 == 2) {
      sides[i] = FitAtEstimate(problem, q, estimate, profile.minimum_cost);
      return;
    }
    const Side side = MakeSide(problem, q, i % 3 == 0 ? -1.0 : 1.0, estimate, covariance, quantile);
    sides[i] = SearchSide(problem, side, profile.minimum_cost);
  };
  tbb::task_arena arena(
      std::max(1, std::min(problem.threads, tbb::this_task_arena::max_concurrency())));
  arena.execute([&] { tbb::parallel_for(size_t{0}, sides.size(), search); });
  for (size_t i = 0; i < sides.size(); i += 3) {
    const int q = quantities[i / 3];
    ProfileInterval& interval =
        q == kEffective ? profile.effective_nonlinearity : profile.parameters[q];
    interval.computed = true;
    interval.low = sides[i].end;
    interval.low_end = sides[i].kind;
    interval.high = sides[i + 1].end;
    interval.high_end = sides[i + 1].kind;
    interval.fits = sides[i].fits + sides[i + 1].fits + sides[i + 2].fits;
    profile.fits += interval.fits;
    for (const SideResult* side : {&sides[i], &sides[i + 1], &sides[i + 2]}) {
      if (!side->lower || (profile.found_lower && side->lower_cost >= profile.lower_cost)) continue;
      profile.found_lower = true;
      profile.lower_cost = side->lower_cost;
      profile.lower_point = side->lower->p;
      profile.lower_while = StringPrintf(
          "profiling %s at %.6g",
          q == kEffective ? "alpha_e" : ParameterName(problem.residual.form, q), side->lower->t);
    }
  }
  return profile;
}

}  // namespace dwellfit
