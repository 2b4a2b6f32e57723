#include "dwellfit/estimator/analysis/parameter_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/level_noise.h"
#include "dwellfit/estimator/analysis/profile_likelihood.h"
#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/residuals/functors/bifurcation_range_penalty.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {
namespace {

std::string JoinNames(ModelForm form, const std::vector<int>& parameters) {
  std::string joined;
  for (size_t i = 0; i < parameters.size(); ++i) {
    if (i > 0) joined += i + 1 == parameters.size() ? " and " : ", ";
    joined += ParameterName(form, parameters[i]);
  }
  return joined;
}

bool IsPair(int a, int b, int first, int second) {
  return (a == first && b == second) || (a == second && b == first);
}

// Whether a and b are delta and alpha, the pair only alpha_e of separates.
bool IsInertiaPair(ModelForm form, int a, int b) {
  return form.has_inertia() && IsPair(a, b, kDelta, kAlpha);
}

// What to do about two free parameters the sweeps hardly separate.
std::string PairAdvice(ModelForm form, int a, int b) {
  if (IsInertiaPair(form, a, b)) {
    return "fix delta (fixed: [delta]) or add a sweep far from this frequency band";
  }
  if (IsPair(a, b, kMu1, kMu2)) {
    return "the damping split is weakly determined: add a sweep at a lower or higher level";
  }
  return "add a sweep that excites them differently (another level or frequency band), or fix "
         "one of them";
}

// What the sweeps cannot see, in plain words. A parameter is implicated when
// its row of `null_space` has a norm of at least kNullDirectionShare
// (independent of the basis the SVD returned).
std::string DescribeNullSpace(ModelForm form, const Eigen::MatrixXd& null_space,
                              const Eigen::VectorXd& unit_scale, const std::vector<int>& free,
                              const Eigen::MatrixXd& column_cosines) {
  std::vector<int> involved;
  std::vector<int> tangent;
  for (int j = 0; j < null_space.rows(); ++j) {
    if (null_space.row(j).norm() >= kNullDirectionShare) {
      involved.push_back(free[j]);
      tangent.push_back(j);
    }
  }
  const int rank_loss = static_cast<int>(null_space.cols());
  std::string text = JoinNames(form, involved) + " cannot be told apart by these sweeps";
  if (rank_loss != 1 || involved.size() != 2) {
    return text + StringPrintf(
                      ": %d combination(s) of them are not determined; fix %d of them or add "
                      "sweeps at other levels and frequencies",
                      rank_loss, rank_loss);
  }
  // Two parameters, one lost direction: their Jacobian columns are parallel
  // (|cosine| = 1), and moving both along the null direction leaves the fit
  // unchanged, so their estimates correlate at the sign of that direction.
  const double cosine = std::abs(column_cosines(tangent[0], tangent[1]));
  const double sign = null_space(tangent[0], 0) * null_space(tangent[1], 0) > 0.0 ? 1.0 : -1.0;
  text += StringPrintf(
      " (a change of one is undone by a change of the other: their correlation is %+.3f)",
      sign * cosine);
  if (IsInertiaPair(form, involved[0], involved[1])) {
    // Along the null direction alpha - (2/3) delta Omega^2 stays constant:
    // d alpha = (2/3) Omega^2 d delta, which gives the Omega the data fix.
    const int d = involved[0] == kDelta ? tangent[0] : tangent[1];
    const int a = involved[0] == kAlpha ? tangent[0] : tangent[1];
    const double omega_squared =
        1.5 * (null_space(a, 0) * unit_scale[a]) / (null_space(d, 0) * unit_scale[d]);
    if (omega_squared > 0.0 && std::isfinite(omega_squared)) {
      text +=
          StringPrintf(": only alpha - (2/3) delta Omega^2 at Omega = 2 pi %.4g Hz is determined",
                       RadPerSecondToHz(std::sqrt(omega_squared)));
    }
  }
  return text + "; " + PairAdvice(form, involved[0], involved[1]);
}

// Counts the fitted dwells past the end of their branch at `estimate`
// (RootStatus::kBranchEnd: the cost has a kink where the fold passes a
// dwell) and warns, naming up to three.
void WarnAboutDwellsPastTheirBranchEnd(const std::vector<const Sweep*>& fitted, ModelForm form,
                                       const ParameterVector& estimate, ParameterUncertainty* u) {
  int count = 0;
  std::string examples;
  for (const Sweep* sweep : fitted) {
    for (const DwellPoint& point : sweep->points) {
      const auto k = ResponseCoefficients<double>::FromParameters(form, estimate.data(),
                                                                  point.drive_frequency_rad_s);
      if (SolveStableRoot(k, point.a_base, point.branch, point.amplitude).status !=
          RootStatus::kBranchEnd) {
        continue;
      }
      if (++count > 3) continue;
      if (!examples.empty()) examples += ", ";
      examples += sweep->kind == SweepKind::kFrequency
                      ? StringPrintf("%s at %.4g Hz", sweep->Name().c_str(),
                                     RadPerSecondToHz(point.drive_frequency_rad_s))
                      : StringPrintf("%s at a_base %.4g", sweep->Name().c_str(), point.a_base);
    }
  }
  u->dwells_past_branch_end = count;
  if (count == 0) return;
  u->warnings.push_back(StringPrintf(
      "%d fitted dwell(s) lie past the end of their branch at the estimate (%s%s): the model's "
      "fold falls short of where they were measured and the fit is not smooth there; where the "
      "sweep's measured jump ends that branch the intervals are widened by the move back to it "
      "(label pulls), elsewhere they may be too narrow; check the branch labels or enable the "
      "branch-stability penalty",
      count, examples.c_str(), count > 3 ? ", ..." : ""));
}

// One enforced jump of the bifurcation-range penalty at the estimate: its
// distance u from the bracket's centre in half-widths and the curvature
// kappa = (1/2) W n (n - 1) u^(n - 2) of its cost (1/2) W u^n along grad u.
struct PenaltyCurvature {
  const Sweep* sweep;
  const JumpBracket* jump;
  ModelForm form;          // the fit's response model
  double distance = 0.0;   // u
  double curvature = 0.0;  // kappa
};

// The penalty's W and n in the fit's last stage that had it; false when
// the penalty is off or no stage had it.
bool PenaltyInFit(const IdentificationOptions& options, const FitSummary* summary, double* weight,
                  int* exponent) {
  if (!options.solve.penalties.bifurcation_range.enabled || summary == nullptr) return false;
  for (auto stage = summary->stages.rbegin(); stage != summary->stages.rend(); ++stage) {
    if (stage->penalty_exponent <= 0) continue;
    *weight = options.solve.penalties.bifurcation_range.weight * stage->penalty_unit;
    *exponent = stage->penalty_exponent;
    return *weight > 0.0 && std::isfinite(*weight);
  }
  return false;
}

// A row whose residual is sqrt(weight) u (BifurcationRangePenalty, n = 2).
ceres::CostFunction* DistanceRow(const PenaltyCurvature& term, double weight) {
  BifurcationRangeOptions reading;
  reading.exponent = 2;
  reading.weight = weight;
  return MakeBifurcationRangePenalty(term.form, *term.sweep, *term.jump, reading);
}

// Every enforced jump's distance and curvature at `estimate`, with warnings
// for folds missing or outside their bracket.
std::vector<PenaltyCurvature> EnforcedJumps(const std::vector<const Sweep*>& fitted, ModelForm form,
                                            const PenaltyOptions& penalties, double weight,
                                            int exponent, const ParameterVector& estimate,
                                            ParameterUncertainty* u) {
  std::vector<PenaltyCurvature> terms;
  for (const Sweep* sweep : fitted) {
    for (const JumpBracket& jump : sweep->jumps) {
      if (!IsEnforced(penalties.bifurcation_range, *sweep, jump)) continue;
      PenaltyCurvature term{sweep, &jump, form};
      const std::unique_ptr<ceres::CostFunction> row(DistanceRow(term, 1.0));
      const double* blocks[] = {estimate.data()};
      const std::string name = sweep->Name() + " " + JumpKindName(jump.kind);
      if (!row->Evaluate(blocks, &term.distance, nullptr) || !std::isfinite(term.distance) ||
          std::abs(term.distance) >= BifurcationRangePenalty::kNoFoldDistance) {
        u->warnings.push_back(name +
                              ": the model has no fold for this enforced jump at the "
                              "estimate; the intervals leave this jump's penalty out");
        continue;
      }
      if (std::abs(term.distance) > 1.0) {
        u->warnings.push_back(StringPrintf(
            "%s: the model's fold lies %.2f half-widths from the centre of its measured bracket, "
            "outside it; the penalty dominates there and the intervals are poor",
            name.c_str(), term.distance));
      }
      term.curvature = 0.5 * weight * exponent * (exponent - 1) *
                       std::pow(std::abs(term.distance), exponent - 2);
      terms.push_back(term);
    }
  }
  return terms;
}

// The covariance's counts, noise, collinearity and warnings into `u`.
void CopyCounts(const BlockCovariance& c, ParameterUncertainty* u) {
  u->num_points = c.num_points;
  u->num_free = c.num_free;
  u->degrees_of_freedom = c.degrees_of_freedom;
  u->noise_known = c.all_standardised;
  u->noise_sigma = c.noise_sigma;
  u->reduced_chi_square = c.reduced_chi_square;
  u->collinearity = c.collinearity;
  u->warnings.insert(u->warnings.begin(), c.warnings.begin(), c.warnings.end());
}

// Standard errors, intervals and correlations from the 6 x 6 covariance.
void CopyIntervals(const BlockCovariance& c, ParameterUncertainty* u) {
  u->interval_quantile = c.interval_quantile;
  u->covariance = c.covariance;
  std::copy_n(c.standard_error.begin(), kNumParameters, u->standard_error.begin());
  std::copy_n(c.ci95_low.begin(), kNumParameters, u->ci95_low.begin());
  std::copy_n(c.ci95_high.begin(), kNumParameters, u->ci95_high.begin());
  for (int a : c.free) {
    for (int b : c.free) {
      const double denominator = u->standard_error[a] * u->standard_error[b];
      u->correlation(a, b) = a == b              ? 1.0
                             : denominator > 0.0 ? u->covariance(a, b) / denominator
                                                 : 0.0;
    }
  }
}

// g = d alpha_e / dp, alpha_e = alpha - (2/3) delta Omega_ref^2 (alpha for
// a member without delta).
Eigen::Matrix<double, kNumParameters, 1> EffectiveNonlinearityGradient(ModelForm form,
                                                                       double omega_ref_rad_s) {
  Eigen::Matrix<double, kNumParameters, 1> g = Eigen::Matrix<double, kNumParameters, 1>::Zero();
  if (form.has_inertia()) g[kDelta] = -(2.0 / 3.0) * omega_ref_rad_s * omega_ref_rad_s;
  g[kAlpha] = 1.0;
  return g;
}

// alpha_e's variance g^T C g.
void SetEffectiveNonlinearity(ParameterUncertainty* u) {
  const Eigen::Matrix<double, kNumParameters, 1> gradient =
      EffectiveNonlinearityGradient(u->form, u->omega_ref_rad_s);
  u->effective_nonlinearity_standard_error =
      std::sqrt(std::max(gradient.dot(u->covariance * gradient), 0.0));
  u->effective_nonlinearity_ci95_low =
      u->effective_nonlinearity - u->interval_quantile * u->effective_nonlinearity_standard_error;
  u->effective_nonlinearity_ci95_high =
      u->effective_nonlinearity + u->interval_quantile * u->effective_nonlinearity_standard_error;
}

// The level's noise (level_noise.h) into `c`: its covariance, standard
// errors, intervals and noise. Returns the term (groups 0: none).
LevelNoise AddLevelNoise(const std::vector<const Sweep*>& fitted,
                         const IdentificationOptions& options, const ParameterVector& estimate,
                         BlockCovariance* c, ParameterUncertainty* u) {
  const LevelNoise level =
      EstimateLevelNoise(fitted, options, estimate, c->covariance, c->noise_sigma, c->data_cost,
                         c->degrees_of_freedom, c->all_standardised);
  if (!level.warning.empty()) u->warnings.push_back(level.warning);
  if (level.groups == 0) return level;
  c->covariance += level.added;
  c->noise_sigma = level.noise_sigma;
  IntervalsFromCovariance(c);
  c->message += StringPrintf("; with the measured level's noise (%d level draws)", level.groups);
  return level;
}

// A profile interval's ends moved out by the level's variance `added` (the
// profile holds the residuals' scatter only): each half-width h becomes
// sqrt(h^2 + q^2 added).
void WidenBy(double estimate, double added, double q, double* low, double* high) {
  const auto widen = [&](double half) {
    return std::sqrt(std::max(half * half + q * q * added, 0.0));
  };
  if (std::isfinite(*low)) *low = estimate - widen(estimate - *low);
  if (std::isfinite(*high)) *high = estimate + widen(*high - estimate);
}

void WidenProfileByLevel(const LevelNoise& level, const ParameterVector& estimate,
                         ParameterUncertainty* u) {
  for (int j = 0; j < kNumParameters; ++j) {
    if (level.added(j, j) == 0.0) continue;
    WidenBy(estimate[j], level.added(j, j), u->interval_quantile, &u->ci95_low[j],
            &u->ci95_high[j]);
  }
  const Eigen::Matrix<double, kNumParameters, 1> g =
      EffectiveNonlinearityGradient(u->form, u->omega_ref_rad_s);
  WidenBy(u->effective_nonlinearity, g.dot(level.added * g), u->interval_quantile,
          &u->effective_nonlinearity_ci95_low, &u->effective_nonlinearity_ci95_high);
}

// Warnings: weakly separated pairs, parameters held by their bound.
void AddPairAndBoundWarnings(const std::vector<int>& free, const ParameterVector& estimate,
                             ParameterUncertainty* u) {
  for (size_t x = 0; x < free.size(); ++x) {
    for (size_t y = x + 1; y < free.size(); ++y) {
      const int a = free[x], b = free[y];
      const double rho = u->correlation(a, b);
      if (std::abs(rho) <= kCorrelationWarning) continue;
      std::string warning =
          StringPrintf("%s and %s correlate at %+.3f: ", ParameterName(u->form, a),
                       ParameterName(u->form, b), rho);
      if (IsInertiaPair(u->form, a, b)) {
        warning += StringPrintf(
            "delta and alpha are weakly separated by these sweeps, while alpha - (2/3) delta "
            "Omega_ref^2 = %.4g +/- %.2g is well determined; ",
            u->effective_nonlinearity, u->effective_nonlinearity_standard_error);
      }
      u->warnings.push_back(warning + PairAdvice(u->form, a, b));
    }
  }
  for (int i : free) {
    const bool bounded = i == kEtaE || i == kMu1 || i == kMu2;
    if (bounded && estimate[i] <= 0.0) {
      u->warnings.push_back(std::string(ParameterName(u->form, i)) +
                            " sits on its bound 0: the data pull it below zero, and its interval "
                            "ignores the bound");
    }
  }
}

// A = J_d^T J_d / s^2 + sum_k (kappa_k / s^2) g_k g_k^T inverted: the
// covariance with each enforced jump's curvature as a row (the caller's
// residual blocks of EstimateBlockCovariance).
BlockCovariance PenalisedCovariance(const std::vector<const Sweep*>& fitted,
                                    const IdentificationOptions& options,
                                    const ParameterVector& estimate, double noise_variance,
                                    const std::vector<PenaltyCurvature>& terms) {
  ParameterVector parameters = estimate;  // the block the problem reads
  FitDescription fit =
      SingleBlockFit(fitted, options.fixed, &parameters, options.solve.residual.form);
  if (!terms.empty()) {
    fit.add_residuals = [&terms, &parameters, noise_variance](ceres::Problem* problem) {
      for (const PenaltyCurvature& term : terms) {
        problem->AddResidualBlock(DistanceRow(term, term.curvature / noise_variance), nullptr,
                                  parameters.data());
      }
    };
  }
  return EstimateBlockCovariance(fit, options.solve.residual);
}

// The dwells' covariance, with the penalty's curvature at each enforced jump
// when the fit had the penalty (C = s^2 H^-1).
BlockCovariance PenaltyCovariance(const std::vector<const Sweep*>& fitted,
                                  const IdentificationOptions& options,
                                  const ParameterVector& estimate, const FitSummary* summary,
                                  const BlockCovariance& data_only, ParameterUncertainty* u) {
  double weight = 0.0;
  int exponent = 0;
  const bool penalty = PenaltyInFit(options, summary, &weight, &exponent);
  if (options.solve.penalties.bifurcation_range.enabled && !penalty) {
    u->warnings.push_back(
        "the bifurcation-range penalty was on, but the fit's penalty weight is not known here: "
        "the intervals are those of the dwells alone and too wide where the penalty constrains "
        "the fit");
  }
  const double noise_variance = data_only.noise_sigma * data_only.noise_sigma;
  if (!penalty || !(noise_variance > 0.0)) return data_only;
  const std::vector<PenaltyCurvature> terms = EnforcedJumps(
      fitted, options.solve.residual.form, options.solve.penalties, weight, exponent, estimate, u);
  if (terms.empty()) return data_only;
  BlockCovariance c = PenalisedCovariance(fitted, options, estimate, noise_variance, terms);
  if (!c.available) {
    u->warnings.push_back(
        "the penalty's curvature could not be combined with the dwells': the linearised intervals "
        "are those of the dwells alone");
    return data_only;
  }
  u->interval_kind = "linearised_with_penalty";
  u->penalty_terms = static_cast<int>(terms.size());
  c.message = data_only.message + StringPrintf(
                                      "; the bifurcation-range penalty's curvature at %d "
                                      "enforced jump(s) included",
                                      u->penalty_terms);
  return c;
}

// The profile problem of the fit's last stage: its penalties at the weights
// it used, Delta = q^2 s^2 / 2. False (with a note in `u`) when the last
// stage is not the vertical error or its penalties are unknown.
bool MakeProfileProblem(const std::vector<const Sweep*>& fitted,
                        const IdentificationOptions& options, const FitSummary* summary,
                        double threshold, int threads, ParameterUncertainty* u,
                        ProfileProblem* problem) {
  const bool penalised = options.solve.penalties.bifurcation_range.enabled ||
                         options.solve.penalties.branch_stability.enabled;
  const StageSummary* last =
      summary != nullptr && !summary->stages.empty() ? &summary->stages.back() : nullptr;
  if (last == nullptr ? penalised : last->residual != ResidualKind::kVertical) {
    u->warnings.push_back(
        last == nullptr
            ? "the fit's penalty weights are not known here: the intervals are the linearised ones"
            : "the fit's last stage is not the vertical error: the intervals are the linearised "
              "ones of the vertical error at the estimate");
    return false;
  }
  problem->fitted = fitted;
  problem->fixed = options.fixed;
  problem->residual = options.solve.residual;
  if (last != nullptr) problem->penalties = last->penalties;
  problem->solver = options.solve.solver;
  problem->omega_ref_rad_s = u->omega_ref_rad_s;
  problem->threshold = threshold;
  problem->threads = threads;
  return problem->threshold > 0.0;
}

// Replaces the intervals in `u` by the profile's; warns where an end is open
// or the two differ by more than kIntervalDisagreement.
void UseProfile(const ProfileLikelihood& profile, ParameterUncertainty* u) {
  u->profile = profile;
  u->interval_kind = "profile_likelihood";
  for (int q = 0; q <= kNumParameters; ++q) {
    const bool effective = q == kNumParameters;
    // Without the inertia delta, alpha_e is alpha, and so is its profile.
    const ProfileInterval& interval = !effective              ? profile.parameters[q]
                                      : u->form.has_inertia() ? profile.effective_nonlinearity
                                                              : profile.parameters[kAlpha];
    if (!interval.computed) continue;
    double& low = effective ? u->effective_nonlinearity_ci95_low : u->ci95_low[q];
    double& high = effective ? u->effective_nonlinearity_ci95_high : u->ci95_high[q];
    const char* name = effective ? "alpha_e" : ParameterName(u->form, q);
    const double ratio = (high - low) / (interval.high - interval.low);
    if (interval.low_end == ProfileEnd::kOpen || interval.high_end == ProfileEnd::kOpen) {
      u->warnings.push_back(StringPrintf(
          "the data do not bound %s: its profile stays below the 95 %% threshold as far as the "
          "search went (%s side); fix it or add sweeps that determine it",
          name, interval.low_end == ProfileEnd::kOpen ? "lower" : "upper"));
    } else if (!(ratio <= kIntervalDisagreement && ratio >= 1.0 / kIntervalDisagreement)) {
      u->warnings.push_back(StringPrintf(
          "%s: the linearised 95 %% interval [%.4g, %.4g] and the profile-likelihood one "
          "[%.4g, %.4g] differ by a factor %.2g in width; the profile is reported",
          name, low, high, interval.low, interval.high, ratio >= 1.0 ? ratio : 1.0 / ratio));
    }
    low = interval.low;
    high = interval.high;
  }
}

// Every linearised interval narrower than kRoundOffShare of its parameter:
// exact data, where a rise of q^2 s^2 / 2 is below the cost's resolution.
bool AtRoundOff(const ParameterUncertainty& u, const ParameterVector& estimate) {
  for (int i = 0; i < kNumParameters; ++i) {
    const double half_width = u.linearised_ci95_high[i] - estimate[i];
    if (half_width > kRoundOffShare * std::abs(estimate[i])) return false;
  }
  return true;
}

// The profile intervals in `u` (which holds the linearised ones), or a note
// in its message why not.
void ProfileIntervals(const std::vector<const Sweep*>& fitted, const IdentificationOptions& options,
                      const ParameterVector& estimate, const FitSummary* summary,
                      const BlockCovariance& c, int threads, ParameterUncertainty* u) {
  if (AtRoundOff(*u, estimate)) {
    u->message +=
        "; the residuals are at round-off (exact data): the linearised intervals are reported";
    return;
  }
  ProfileProblem problem;
  const double threshold = 0.5 * std::pow(c.interval_quantile * c.noise_sigma, 2);
  if (!MakeProfileProblem(fitted, options, summary, threshold, threads, u, &problem)) return;
  UseProfile(ProfileCost(problem, estimate, c.covariance, c.interval_quantile), u);
}

// Fits the last stage again from `start`; where that ends below the result's
// cost, the result moves there and its message says `why`. Whether it moved.
bool MoveToLower(const ProfileProblem& problem, const ParameterVector& start,
                 const std::string& why, IdentificationResult* result) {
  ParameterVector p = start;
  const double cost = RefitProfileProblem(problem, &p);
  if (!(cost < result->final_cost * (1.0 - kLowerCostTolerance))) return false;
  result->message += StringPrintf("; %s: the cost fell from %.10g to %.10g", why.c_str(),
                                  result->final_cost, cost);
  result->parameters = p;
  result->final_cost = cost;
  if (!result->stages.empty()) result->stages.back().values.assign(p.begin(), p.end());
  return true;
}

}  // namespace

// In IntervalMethod's order.
constexpr const char* kIntervalMethodNames[] = {"data_only", "linearised", "profile"};

const char* IntervalMethodName(IntervalMethod method) {
  return NameOf(kIntervalMethodNames, method);
}

bool ParseIntervalMethod(const std::string& name, IntervalMethod* method) {
  return FromName(name, kIntervalMethodNames, method);
}

ParameterUncertainty EstimateUncertainty(const std::vector<const Sweep*>& fitted,
                                         const IdentificationOptions& options,
                                         const ParameterVector& estimate, double omega_ref_rad_s,
                                         const FitSummary* summary, IntervalMethod method,
                                         int threads) {
  ParameterUncertainty u;
  u.form = options.solve.residual.form;
  if (!(omega_ref_rad_s > 0.0)) omega_ref_rad_s = estimate[kNaturalFrequency];
  u.omega_ref_rad_s = omega_ref_rad_s;
  u.effective_nonlinearity = EffectiveNonlinearity(u.form, estimate, omega_ref_rad_s);
  if (!std::isfinite(u.effective_nonlinearity)) u.effective_nonlinearity = 0.0;

  const BlockCovariance data_only = PenalisedCovariance(fitted, options, estimate, 1.0, {});
  const BlockCovariance without_level =
      method == IntervalMethod::kDataOnly || !data_only.available
          ? data_only
          : PenaltyCovariance(fitted, options, estimate, summary, data_only, &u);
  BlockCovariance c = without_level;
  const LevelNoise level =
      c.available ? AddLevelNoise(fitted, options, estimate, &c, &u) : LevelNoise();
  CopyCounts(c, &u);
  if (c.evaluated)
    WarnAboutDwellsPastTheirBranchEnd(fitted, options.solve.residual.form, estimate, &u);
  if (!c.available) {
    // Entries the data cannot tell apart are named in the model's terms.
    u.message = c.null_space.cols() == 0 ? c.message
                                         : DescribeNullSpace(u.form, c.null_space, c.unit_scale,
                                                             c.free, c.column_cosines) +
                                               StringPrintf(" (collinearity %.3g, limit %.3g)",
                                                            c.collinearity, kMaxCollinearity);
    return u;
  }
  CopyIntervals(c, &u);
  SetEffectiveNonlinearity(&u);
  AddPairAndBoundWarnings(c.free, estimate, &u);
  u.linearised_ci95_low = u.ci95_low;
  u.linearised_ci95_high = u.ci95_high;
  u.effective_nonlinearity_linearised_ci95_low = u.effective_nonlinearity_ci95_low;
  u.effective_nonlinearity_linearised_ci95_high = u.effective_nonlinearity_ci95_high;
  u.available = true;
  u.message = c.message;
  if (method == IntervalMethod::kProfile) {
    ProfileIntervals(fitted, options, estimate, summary, without_level, threads, &u);
  }
  if (u.interval_kind == "profile_likelihood") {
    u.message +=
        StringPrintf("; profile-likelihood intervals from %d constrained fits", u.profile.fits);
    if (level.groups > 0) {
      WidenProfileByLevel(level, estimate, &u);
      u.message += ", widened by the level's noise";
    }
  }
  if (!u.warnings.empty())
    u.message += StringPrintf("; %d warning(s)", static_cast<int>(u.warnings.size()));
  return u;
}

ParameterUncertainty EstimateUncertaintyAtMinimum(const std::vector<const Sweep*>& fitted,
                                                  const IdentificationOptions& options,
                                                  double omega_ref_rad_s,
                                                  IdentificationResult* result, int threads) {
  ProfileProblem problem;
  ParameterUncertainty u;
  u.omega_ref_rad_s =
      omega_ref_rad_s > 0.0 ? omega_ref_rad_s : result->parameters[kNaturalFrequency];
  const bool profiled = result->IsSolutionUsable() &&
                        MakeProfileProblem(fitted, options, result, 1.0, 1, &u, &problem);
  if (profiled) {
    u = EstimateUncertainty(fitted, options, result->parameters, omega_ref_rad_s, result,
                            IntervalMethod::kLinearised);
  }
  // Exact data: nothing to profile (EstimateUncertainty says so).
  if (!profiled || !u.available || AtRoundOff(u, result->parameters)) {
    return EstimateUncertainty(fitted, options, result->parameters, omega_ref_rad_s, result,
                               IntervalMethod::kProfile, threads);
  }
  // The profile's own solve from the estimate first: where the staged
  // solve stopped short of the minimum, one fit instead of a profile.
  MoveToLower(problem, result->parameters, "the last stage solved again", result);
  for (int round = 0;; ++round) {
    u = EstimateUncertainty(fitted, options, result->parameters, omega_ref_rad_s, result,
                            IntervalMethod::kProfile, threads);
    if (!u.profile.found_lower) break;
    const double before = result->final_cost;
    if (round < kMaxRefits &&
        MoveToLower(problem, u.profile.lower_point, u.profile.lower_while, result) &&
        before - result->final_cost < kReprofileShare * u.profile.threshold) {
      // A small step down: the profile's ends stand (each within about
      // kReprofileShare / 2 of its width), beside the linearisation at the
      // new point.
      ProfileLikelihood profile = u.profile;
      profile.found_lower = false;
      profile.minimum_cost = result->final_cost;
      u = EstimateUncertainty(fitted, options, result->parameters, omega_ref_rad_s, result,
                              IntervalMethod::kLinearised, threads);
      if (u.available) UseProfile(profile, &u);
      break;
    }
    if (round == kMaxRefits || result->final_cost == before) {
      // Still not a minimum: say so, whatever the solver's tests said.
      if (result->status == FitStatus::kConverged) result->status = FitStatus::kNoConvergence;
      result->converged = false;
      result->not_minimum =
          u.profile.lower_while + StringPrintf(" found a lower cost (%.10g)", u.profile.lower_cost);
      result->message = "not a minimum: " + result->not_minimum + "; " + result->message;
      u.warnings.push_back("the reported point is not a minimum of the cost: " +
                           result->not_minimum);
      return u;
    }
  }
  // The profiles found no lower cost: the point is a minimum, whatever the
  // staged solve's own check said of where it ended.
  if (result->status == FitStatus::kNoConvergence && !result->not_minimum.empty()) {
    const std::string prefix = "not a minimum: " + result->not_minimum + "; ";
    if (result->message.compare(0, prefix.size(), prefix) == 0) {
      result->message = result->message.substr(prefix.size()) + "; the staged solve ended where " +
                        result->not_minimum;
    }
    result->status = FitStatus::kConverged;
    result->converged = true;
    result->message += "; no profile found a lower cost: a minimum";
    result->not_minimum.clear();
  }
  return u;
}

}  // namespace dwellfit
