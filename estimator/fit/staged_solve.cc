#include "dwellfit/estimator/fit/staged_solve.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "boost/algorithm/string/join.hpp"
#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/estimator/fit/bound_rest_watcher.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/fit/stage_problem.h"
#include "dwellfit/estimator/fit/valley_polish.h"
#include "glog/logging.h"

namespace dwellfit {

const char* FitStatusName(FitStatus status) {
  // In enumerator order.
  constexpr const char* kNames[] = {"converged", "no_convergence", "failure", "invalid_input",
                                    "unidentifiable"};
  return NameOf(kNames, status);
}

ceres::Solver::Options MakeSolverOptions(const SolverSettings& settings) {
  ceres::Solver::Options options;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  SetConvergenceTests(settings, &options);
  // ParallelResidualEvaluator evaluates on threads in a fixed order; Ceres'
  // own threads would sum in an order that varies between runs.
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.use_nonmonotonic_steps = settings.nonmonotonic_steps;
  // Ceres' default of 5 cuts the non-monotonic excursions short on the
  // narrow valleys of measured data with penalties.
  options.max_consecutive_nonmonotonic_steps = 20;
  return options;
}

bool ReflectDampingIntoPhysicalRange(const std::vector<double*>& eta_e_entries,
                                     const std::vector<double*>& damping_entries) {
  bool changed = false;
  for (double* eta_e : eta_e_entries) {
    changed = changed || *eta_e < 0.0;
    *eta_e = std::abs(*eta_e);
  }
  const bool none_positive = std::none_of(damping_entries.begin(), damping_entries.end(),
                                          [](const double* mu) { return *mu > 0.0; });
  for (double* mu : damping_entries) {
    const double before = *mu;
    if (none_positive) *mu = -*mu;
    *mu = std::max(*mu, 0.0);
    changed = changed || *mu != before;
  }
  return changed;
}

namespace {

bool PenaltiesEnabled(const PenaltyOptions& penalties) {
  return penalties.bifurcation_range.enabled || penalties.branch_stability.enabled;
}

constexpr int kStepsAtBoundBeforeHolding = 5;  // successful steps before an entry is held
constexpr int kMaxSolvesPerStage = 12;
constexpr int kMaxPolishesPerStage = 2;

// The stage-independent part of a staged solve.
struct SolveContext {
  const FitDescription& fit;
  const StagedSolveOptions& options;
  std::vector<double> scale;  // per ambient entry
  int threads = 1;
};

bool IsBranchLabelled(ResidualKind kind) {
  return kind == ResidualKind::kVertical || kind == ResidualKind::kAllRoots;
}

// The solver options of a stage of residual `kind`.
ceres::Solver::Options StageSolverOptions(ResidualKind kind, const SolverSettings& settings) {
  ceres::Solver::Options options = MakeSolverOptions(settings);
  // No projected line search: on the vertical error, whose gradient spans
  // some twenty decades, its interpolation now and then cuts a good step to
  // nothing and ends the solve far from a minimum (the measured beam: in a
  // basin of ten times the cost). Ceres still projects steps onto the
  // bounds. The algebraic stage keeps it: its full steps from a rough
  // start overshoot by orders of magnitude.
  if (IsBranchLabelled(kind)) options.max_num_line_search_step_size_iterations = 0;
  return options;
}

// One solve of `problem`; `*resting` is the entry that stopped it by
// resting on its bound; `creep`, when given, stops a solve that creeps.
ceres::Solver::Summary SolveOnce(ResidualKind kind, const SolverSettings& settings,
                                 StageProblem* problem, std::optional<int>* resting,
                                 CreepWatcher* creep) {
  problem->Configure();
  BoundRestWatcher watcher(problem->WatchedBounds(), kStepsAtBoundBeforeHolding);
  ceres::Solver::Options options = StageSolverOptions(kind, settings);
  options.callbacks.push_back(&watcher);
  if (creep != nullptr) options.callbacks.push_back(creep);
  options.update_state_every_iteration = true;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem->problem(), &summary);
  *resting = watcher.resting();
  // A non-monotonic excursion rested on the bound, the best point so far
  // did not: go on from where it rests (the measured beam: 11 steps, against
  // about 100 from the best point).
  if (watcher.resting_at_iterate()) problem->MoveToIterate();
  return summary;
}

// Releases, once each, the held entries whose cost falls as they leave
// their bound (d cost / d p < 0 at p = 0). Returns whether any was.
bool ReleaseHeld(StageProblem* problem, std::vector<bool>* held, std::vector<bool>* released) {
  bool releasable = false;  // without such an entry the gradient is not needed
  for (size_t i = 0; i < held->size(); ++i)
    releasable = releasable || ((*held)[i] && !(*released)[i]);
  if (!releasable) return false;
  std::vector<double> gradient;
  if (!problem->CostGradient(&gradient)) return false;
  bool released_any = false;
  for (size_t i = 0; i < held->size(); ++i) {
    if ((*held)[i] && !(*released)[i] && gradient[i] < 0.0) {
      (*held)[i] = false;
      (*released)[i] = true;
      released_any = true;
    }
  }
  return released_any;
}

// The penalties weighed in the data's units where the stage starts: the
// bifurcation-range terms against the dwells' sum of squares, each
// branch-stability term (one per dwell) against a dwell's mean square.
PenaltyOptions WeighPenalties(const PenaltyOptions& penalties, StageProblem* problem,
                              StageSummary* stage) {
  stage->penalty_unit = 2.0 * problem->DataCost();
  stage->penalty_exponent =
      penalties.bifurcation_range.enabled ? penalties.bifurcation_range.exponent : 0;
  PenaltyOptions weighted = penalties;
  weighted.bifurcation_range.weight *= stage->penalty_unit;
  weighted.branch_stability.weight *= stage->penalty_unit / problem->dwells();
  return weighted;
}

// The entries of `fit` that hold one of `parameters` in some dataset, each once.
std::vector<double*> EntriesOf(const FitDescription& fit, std::initializer_list<int> parameters) {
  const std::vector<bool> holding = fit.EntriesHolding(parameters);
  std::vector<double*> entries;
  for (size_t b = 0; b < fit.blocks.size(); ++b) {
    for (int i = 0; i < fit.blocks[b].size; ++i) {
      if (holding[fit.Offset(static_cast<int>(b)) + i]) entries.push_back(fit.blocks[b].values + i);
    }
  }
  return entries;
}

// ReflectDampingIntoPhysicalRange on the entries of `fit`.
bool ReflectDamping(const FitDescription& fit) {
  return ReflectDampingIntoPhysicalRange(EntriesOf(fit, {kEtaE}), EntriesOf(fit, {kMu1, kMu2}));
}

void RecordSolve(const ceres::Solver::Summary& summary, int round, const PenaltyOptions& penalties,
                 StageProblem* problem, StageSummary* stage) {
  if (round == 0) stage->initial_cost = summary.initial_cost;
  stage->final_cost = summary.final_cost;
  stage->iterations += std::max(static_cast<int>(summary.iterations.size()) - 1, 0);
  ++stage->solves;
  stage->converged = summary.termination_type == ceres::CONVERGENCE;
  stage->brief_report = summary.BriefReport();
  stage->final_data_cost = problem->DataCost();
  stage->final_penalty_cost = problem->PenaltyCost();
  stage->missing_folds = problem->MissingFolds(penalties.bifurcation_range);
}

// "eta_e 100, mu1 0.2, ..., omega 251.3 rad/s": every entry of `fit` at
// `values`, natural frequencies with their unit.
std::string DescribeValues(const FitDescription& fit, const std::vector<double>& values) {
  const std::vector<bool> natural_frequency = fit.EntriesHolding({kNaturalFrequency});
  std::ostringstream text;
  for (size_t i = 0; i < values.size(); ++i) {
    text << (i > 0 ? ", " : "") << fit.EntryName(static_cast<int>(i)) << " " << values[i]
         << (natural_frequency[i] ? " rad/s" : "");
  }
  return text.str();
}

// Whether a solve from `start` could not evaluate its cost (`*failure`).
bool SolveFailed(const ceres::Solver::Summary& summary, ResidualKind kind,
                 const FitDescription& fit, const std::vector<double>& start, StageProblem* problem,
                 std::string* failure) {
  if (summary.IsSolutionUsable() && std::isfinite(summary.final_cost)) return false;
  *failure = std::string("the ") + ResidualKindName(kind) + " stage cannot evaluate its cost at " +
             DescribeValues(fit, start) + ": " + problem->DescribeFailure(summary.message);
  return true;
}

StageSetup MakeSetup(const SolveContext& context, ResidualKind kind) {
  StageSetup setup;
  setup.residuals.residual = kind;
  setup.residuals.residual_options = context.options.residual;
  setup.scale = context.scale;
  setup.bound_damping = kind != ResidualKind::kAlgebraic;
  setup.num_threads = context.threads;
  return setup;
}

// The valley polish of a solve that crept, recorded in the stage.
void Polish(const SolveContext& context, const SolverSettings& settings, StageProblem* problem,
            StageSummary* stage) {
  std::vector<double*> blocks;
  for (const FitBlock& block : context.fit.blocks) {
    if (!problem->problem()->IsParameterBlockConstant(block.values)) blocks.push_back(block.values);
  }
  const ValleyPolish polish = PolishAlongValley(problem->problem(), blocks, settings);
  stage->iterations += polish.iterations;
  std::ostringstream note;
  note << (stage->note.empty() ? "" : "; ") << "valley polish after " << kCreepSteps
       << " steps in a row that lowered the cost over " << kCreepRatio
       << " times the model's prediction: " << polish.message;
  stage->note += note.str();
  VLOG(1) << ResidualKindName(stage->residual) << " stage: " << note.str();
}

// One stage: the residual `kind` (with `penalties` on a vertical stage) from
// the blocks' values, which it updates, with the active set of the header.
// False when a solve failed (`*failure`). `rated`, when given, is the
// problem of the dwells alone ChooseStart rated the start on, solved on
// instead of a new one. `start_only`: its end only starts a later stage
// (SolverSettings::start_function_tolerance). Every solve runs on the same
// problem, held entries reconfigured (StageProblem::Hold), so the values
// where the last solve ended are not evaluated again.
bool RunStage(const SolveContext& context, ResidualKind kind, const PenaltyOptions& penalties,
              bool start_only, StageSummary* stage, std::string* failure,
              std::unique_ptr<StageProblem> rated = nullptr) {
  SolverSettings settings = context.options.solver;
  if (start_only) settings.function_tolerance = settings.start_function_tolerance;
  // The algebraic stage takes the enforced jumps' fold conditions, unweighted
  // (ProblemBuilder::AddPenalties); the all-roots stage the penalties.
  const bool fold_conditions =
      kind == ResidualKind::kAlgebraic && penalties.bifurcation_range.enabled;
  const bool with_penalties = IsBranchLabelled(kind) && PenaltiesEnabled(penalties);
  const int entries = context.fit.NumEntries();
  std::vector<bool> held(entries, false);
  std::vector<bool> released(entries, false);
  int polishes = 0;
  stage->residual = kind;
  std::unique_ptr<StageProblem> assembled =
      rated != nullptr ? std::move(rated)
                       : std::make_unique<StageProblem>(context.fit, MakeSetup(context, kind));
  StageProblem& problem = *assembled;
  const PenaltyOptions weighted =
      with_penalties ? WeighPenalties(penalties, &problem, stage) : penalties;
  if (with_penalties || fold_conditions) problem.AddPenalties(weighted);
  if (with_penalties) stage->penalties = weighted;
  problem.AddCallerResiduals();
  stage->residual_blocks = problem.dwells();
  for (int round = 0;; ++round) {
    problem.Hold(held);
    if (round > 0) problem.EvaluateAfresh();
    std::optional<int> resting;
    const std::vector<double> start = context.fit.Values();
    CreepWatcher creep(kCreepSteps, kCreepRatio);
    const bool watch_creep =
        settings.valley_polish && IsBranchLabelled(kind) && polishes < kMaxPolishesPerStage;
    const ceres::Solver::Summary summary =
        SolveOnce(kind, settings, &problem, &resting, watch_creep ? &creep : nullptr);
    VLOG(2) << ResidualKindName(kind) << " stage, solve " << round + 1 << ": "
            << summary.BriefReport();
    RecordSolve(summary, round, with_penalties ? penalties : PenaltyOptions{}, &problem, stage);
    if (SolveFailed(summary, kind, context.fit, start, &problem, failure)) {
      stage->converged = false;
      return false;
    }
    // Each entry is held at most twice and released once: never reached.
    if (round + 1 >= kMaxSolvesPerStage) break;
    if (resting) {
      held[*resting] = true;
      VLOG(1) << ResidualKindName(kind) << " stage: holding " << context.fit.EntryName(*resting)
              << " at its bound";
      continue;
    }
    if (creep.creeping()) {
      ++polishes;
      Polish(context, settings, &problem, stage);
      continue;
    }
    if (!ReleaseHeld(&problem, &held, &released)) break;
  }
  for (int i = 0; i < entries; ++i) {
    if (held[i]) stage->held_at_bound.push_back(i);
  }
  if (kind == ResidualKind::kAlgebraic && ReflectDamping(context.fit)) {  // unbounded damping
    VLOG(1) << "reflected the " << ResidualKindName(kind) << " stage's damping";
  }
  stage->values = context.fit.Values();
  VLOG(1) << ResidualKindName(kind) << " stage: " << stage->brief_report;
  return true;
}

// A step unit for a parameter that starts at 0, independent of the units of
// a and time (docs/model.md, "Units"): delta like |alpha| / w^2, alpha like
// w^2 / a_max^2 / 10 (a tenth of the linear stiffness at the largest
// amplitude), mu2 like mu1 / a_max, mu1 like w / 1000; a member's own terms
// (model_form.h) alike: mu3 like mu1 / a_max^2, alpha5 like alpha / a_max^2.
double NaturalScale(int parameter, const ParameterVector& p, double a_max, ModelForm form) {
  const double w = std::abs(p[kNaturalFrequency]);
  const double mu1 = p[kMu1] != 0.0 ? std::abs(p[kMu1]) : 1e-3 * w;
  if (parameter == kMu3 && form.cubic_damping()) return mu1 / (a_max * a_max);
  if (parameter == kAlpha5 && form.quintic_stiffness()) {
    return NaturalScale(kAlpha, p, a_max, form) / (a_max * a_max);
  }
  switch (parameter) {
    case kDelta:
      return p[kAlpha] != 0.0 ? std::abs(p[kAlpha]) / (w * w) : 0.1 / (a_max * a_max);
    case kAlpha:
      return 0.1 * w * w / (a_max * a_max);
    case kMu2:
      return mu1 / a_max;
    case kMu1:
      return mu1;
    default:
      return 1.0;
  }
}

// The step unit of every entry: its scale when given, else |value at the
// start|, for 0 its NaturalScale in the first dataset that maps it (else 1).
std::vector<double> StartScale(const FitDescription& fit, ModelForm form) {
  std::vector<double> scale = fit.Values();
  for (double& value : scale) value = std::abs(value);
  for (const FitDataset& dataset : fit.datasets) {
    const ParameterVector p = LayoutOf(fit, dataset.parameters).Values();
    double a_max = 0.0;
    for (const Sweep* sweep : dataset.sweeps) {
      for (const DwellPoint& point : sweep->points) a_max = std::max(a_max, point.amplitude);
    }
    for (int i = 0; i < kNumParameters; ++i) {
      const int entry = fit.AmbientIndex(dataset.parameters[i]);
      if (entry < 0 || scale[entry] != 0.0) continue;
      const double natural = a_max > 0.0 ? NaturalScale(i, p, a_max, form) : 1.0;
      scale[entry] = std::isfinite(natural) && natural > 0.0 ? natural : 1.0;
    }
  }
  int entry = 0;
  for (const FitBlock& block : fit.blocks) {
    for (int i = 0; i < block.size; ++i, ++entry) {
      if (!block.scale.empty()) scale[entry] = block.scale[i];
      if (scale[entry] == 0.0) scale[entry] = 1.0;
    }
  }
  return scale;
}

// How good a point is as the start of a branch-labelled stage: fewer
// enforced folds missing, then a lower cost of the dwells.
struct StartRating {
  std::vector<std::string> missing_folds;
  double data_cost = 0.0;

  bool BetterThan(const StartRating& other) const {
    return std::make_pair(missing_folds.size(), data_cost) <
           std::make_pair(other.missing_folds.size(), other.data_cost);
  }
};

// Rates `values` (written into the blocks) on `problem`, the stage's
// problem of the dwells alone.
StartRating RateStart(const SolveContext& context, StageProblem* problem,
                      const std::vector<double>& values) {
  context.fit.SetValues(values);
  problem->EvaluateAfresh();
  return {problem->MissingFolds(context.options.penalties.bifurcation_range), problem->DataCost()};
}

// "the dwells' vertical cost is 8.77", after the missing folds, if any.
std::string DescribeRating(ResidualKind kind, const StartRating& rating) {
  std::ostringstream text;
  if (!rating.missing_folds.empty())
    text << "it lacks " << boost::algorithm::join(rating.missing_folds, "; ") << "; ";
  text << "the dwells' " << ResidualKindName(kind) << " cost is " << rating.data_cost;
  return text.str();
}

// The start stage (header). One that cannot evaluate its cost is recorded
// and passed over, the blocks back at the given start. Returns whether it
// ended usably.
bool RunStartStage(const SolveContext& context, ResidualKind first, FitSummary* summary) {
  const std::vector<double> given = context.fit.Values();
  summary->stages.emplace_back();
  StageSummary& stage = summary->stages.back();
  stage.start_stage = true;
  stage.note = std::string(
                   "start stage: the algebraic fit from the given start, whose end is a "
                   "candidate start for the first (") +
               ResidualKindName(first) + ") stage";
  std::string failure;
  if (RunStage(context, ResidualKind::kAlgebraic, PenaltyOptions{}, /*start_only=*/true, &stage,
               &failure)) {
    return true;
  }
  stage.note += "; it failed (" + failure + "), so the first stage starts at the given start";
  context.fit.SetValues(given);
  return false;
}

// The note of a branch-labelled stage choosing between `previous` (where
// the previous stage started) and `ended` (where it ended).
std::string StartNote(ResidualKind kind, bool after_start_stage, bool previous_chosen,
                      const StartRating& previous, const StartRating& ended) {
  const std::string ratings = DescribeRating(kind, ended) + " (at " +
                              (after_start_stage ? "the given start" : "its start") + ": " +
                              DescribeRating(kind, previous) + ")";
  if (after_start_stage) {
    return (previous_chosen ? "started at the given start, not where the start stage ended, "
                              "since where it ended "
                            : "started where the start stage ended, since there ") +
           ratings;
  }
  return previous_chosen ? "started where the previous stage started, since at its end " + ratings
                         : "";
}

// Where a branch-labelled stage starts (the header's choice between where
// the previous stage started and ended, and the fold stage, once per
// solve). Leaves the blocks at the chosen start, and in `rated` the problem
// the points were rated on, for RunStage.
struct StartRequest {
  ResidualKind kind = ResidualKind::kVertical;  // the stage's residual
  // Where the previous stage started; null when there is none to compare.
  const std::vector<double>* previous_start = nullptr;
  bool after_start_stage = false;  // the previous stage is the start stage
  bool fold_stage_ran = false;     // a fold stage already ran in this solve
};
struct ChosenStart {
  std::optional<StageSummary> fold_stage;  // the fold stage, when one ran
  std::string note;                        // why the start was chosen, for the stage
  std::string failure;                     // why the fold stage failed ("" when it did not)
  std::unique_ptr<StageProblem> rated;
};
ChosenStart ChooseStart(const SolveContext& context, const StartRequest& request) {
  const ResidualKind kind = request.kind;
  const std::vector<double>* previous_start = request.previous_start;
  ChosenStart chosen;
  std::vector<double> best = context.fit.Values();
  chosen.rated = std::make_unique<StageProblem>(context.fit, MakeSetup(context, kind));
  StageProblem* problem = chosen.rated.get();
  // The previous start first, so that the problem ends holding the values
  // at the usual start, where the previous stage ended.
  std::optional<StartRating> earlier;
  if (previous_start != nullptr) earlier = RateStart(context, problem, *previous_start);
  StartRating rating = RateStart(context, problem, best);
  std::vector<double> last_rated = best;
  if (earlier) {
    const bool earlier_better = earlier->BetterThan(rating);
    chosen.note = StartNote(kind, request.after_start_stage, earlier_better, *earlier, rating);
    if (earlier_better) {
      best = *previous_start;
      rating = *earlier;
    }
  }
  if (kind == ResidualKind::kVertical && !rating.missing_folds.empty() && !request.fold_stage_ran) {
    context.fit.SetValues(best);
    StageSummary& fold_stage = chosen.fold_stage.emplace();
    fold_stage.fold_stage = true;
    fold_stage.note = "fold stage: the vertical stage's start lacks " +
                      boost::algorithm::join(rating.missing_folds, "; ");
    if (!RunStage(context, ResidualKind::kAlgebraic, context.options.penalties, /*start_only=*/true,
                  &fold_stage, &chosen.failure)) {
      return chosen;
    }
    const std::vector<double> after = context.fit.Values();
    const StartRating folded = RateStart(context, problem, after);
    last_rated = after;
    if (folded.BetterThan(rating)) {
      chosen.note = chosen.note.empty()
                        ? "started where the fold stage ended"
                        : chosen.note +
                              "; then, that start lacking an enforced fold, where the "
                              "fold stage ended";
      best = after;
    }
  }
  context.fit.SetValues(best);
  if (best != last_rated) problem->EvaluateAfresh();
  return chosen;
}

// The minimum check's step along an entry, in its step unit.
constexpr double kMinimumCheckStep = 1e-4;
// A cost lower by more than this many function tolerances (shares of the
// cost) is a lower point; less is within the convergence test.
constexpr double kMinimumCheckTolerances = 10.0;

// The lowest cost a step of kMinimumCheckStep along one free entry, either
// way, reaches from where the fit ended (bounds kept), when lower than the
// cost there; else nullopt. The blocks are left as they were.
struct Descent {
  std::vector<double> values;
  double cost = 0.0;
  double from_cost = 0.0;
  int entry = 0;
  double sign = 1.0;
};
std::optional<Descent> FindDescent(const SolveContext& context, const StageSummary& last) {
  StageProblem problem(context.fit, MakeSetup(context, last.residual));
  if (PenaltiesEnabled(last.penalties)) problem.AddPenalties(last.penalties);
  problem.AddCallerResiduals();
  const std::vector<double> start = context.fit.Values();
  const double base = problem.TotalCost();
  if (!std::isfinite(base)) return std::nullopt;
  const double tolerance = kMinimumCheckTolerances * context.options.solver.function_tolerance;
  const std::vector<bool> fixed = context.fit.FixedEntries();
  const std::vector<bool> bounded = context.fit.EntriesHolding({kEtaE, kMu1, kMu2});
  std::optional<Descent> best;
  for (size_t i = 0; i < start.size(); ++i) {
    if (fixed[i]) continue;
    for (double sign : {-1.0, 1.0}) {
      std::vector<double> point = start;
      point[i] += sign * kMinimumCheckStep * context.scale[i];
      if (bounded[i] && point[i] < 0.0) point[i] = 0.0;
      if (point[i] == start[i]) continue;
      context.fit.SetValues(point);
      problem.EvaluateAfresh();
      const double cost = problem.TotalCost();
      if (cost < base * (1.0 - tolerance) && (!best || cost < best->cost)) {
        best = Descent{point, cost, base, static_cast<int>(i), sign};
      }
    }
  }
  context.fit.SetValues(start);
  return best;
}

// The last stage solved again from a point the minimum check found lower:
// one solve with the stage's weighed penalties, without the active set,
// stepped in units of where it stands (the start's can be decades off: the
// measured beam's alpha goes from 7.85e11 to 1.5e11). Where the stage
// stopped on the function tolerance along a valley (the measured beam:
// 81.59556), this reaches its floor (81.5887). False when it cannot
// evaluate the cost (`*failure`).
bool SolveFromDescent(const SolveContext& context, const StageSummary& last, StageSummary* again,
                      std::string* failure) {
  std::vector<double> scale = context.fit.Values();
  for (double& value : scale) value = value != 0.0 ? std::abs(value) : 1.0;
  const SolveContext rescaled{context.fit, context.options, scale, context.threads};
  StageProblem problem(context.fit, MakeSetup(rescaled, last.residual));
  if (PenaltiesEnabled(last.penalties)) problem.AddPenalties(last.penalties);
  problem.AddCallerResiduals();
  problem.Configure();
  const std::vector<double> start = context.fit.Values();
  const ceres::Solver::Options options = StageSolverOptions(last.residual, context.options.solver);
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem.problem(), &summary);
  again->residual = last.residual;
  RecordSolve(summary, 0, last.penalties, &problem, again);
  again->residual_blocks = problem.dwells();
  if (SolveFailed(summary, last.residual, context.fit, start, &problem, failure)) return false;
  if (last.residual == ResidualKind::kAlgebraic) ReflectDamping(context.fit);
  again->values = context.fit.Values();
  return true;
}

// The minimum check: where a step lowers the cost (FindDescent), the last
// stage solves again from there, and the check runs once more. Returns why
// the point is not a minimum ("" when it is). Why that solve failed, when it
// did, in `*failure`.
std::string CheckMinimum(const SolveContext& context, FitSummary* summary, std::string* failure) {
  for (int round = 0; round < 2; ++round) {
    const StageSummary last = summary->stages.back();
    const std::optional<Descent> descent = FindDescent(context, last);
    if (!descent) return "";
    std::ostringstream note;
    note << "the minimum check: the cost falls from " << descent->from_cost << " to "
         << descent->cost << " as " << context.fit.EntryName(descent->entry)
         << (descent->sign > 0 ? " rises" : " falls");
    if (round == 1) return note.str();
    context.fit.SetValues(descent->values);
    summary->stages.emplace_back();
    StageSummary& again = summary->stages.back();
    again.note = note.str() + "; solved again from there";
    again.penalty_unit = last.penalty_unit;
    again.penalty_exponent = last.penalty_exponent;
    again.penalties = last.penalties;
    if (!SolveFromDescent(context, last, &again, failure)) return "";
  }
  return "";
}

// The summary of a solve that could not evaluate its cost.
FitSummary EvaluationFailed(const std::string& why, FitSummary* summary) {
  summary->status = FitStatus::kFailure;
  summary->evaluation_failed = true;
  summary->message = why;
  summary->final_cost = summary->stages.back().final_cost;
  return std::move(*summary);
}

// Status and message from how the last stage ended (header).
void Conclude(const FitDescription& fit, FitSummary* summary) {
  const StageSummary& last = summary->stages.back();
  for (const StageSummary& stage : summary->stages) summary->iterations += stage.iterations;
  summary->residual_blocks = last.residual_blocks;
  summary->final_cost = last.final_cost;
  summary->converged = last.converged;
  summary->status = last.converged ? FitStatus::kConverged : FitStatus::kNoConvergence;
  std::ostringstream message;
  message << summary->stages.size() << " stage(s), " << summary->iterations
          << " iterations, final cost " << summary->final_cost << "; the last ("
          << ResidualKindName(last.residual) << ") "
          << (last.converged ? "converged" : "stopped without meeting a convergence test") << ": "
          << last.brief_report;
  // G depends on w only through w^2: a negative w is the same model.
  for (double* w : EntriesOf(fit, {kNaturalFrequency})) *w = std::abs(*w);
  const std::vector<double*> eta_e = EntriesOf(fit, {kEtaE});
  const std::vector<double> values = fit.Values();
  std::string failure;
  if (!std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); }) ||
      !std::isfinite(summary->final_cost)) {
    failure = "the fit ended at values that are not finite";
  } else if (std::any_of(eta_e.begin(), eta_e.end(), [](const double* e) { return !(*e > 0.0); })) {
    failure = "the fit ended at eta_e = 0, where the model has no forcing";
  } else if (!last.missing_folds.empty()) {
    failure = "the fit ended without the enforced fold(s) " +
              boost::algorithm::join(last.missing_folds, "; ") +
              ": the bifurcation-range penalty could not bring them in (start closer, "
              "enforce fewer jumps, or free more parameters)";
  } else if (last.final_penalty_cost > std::max(last.final_data_cost, last.penalty_unit)) {
    std::ostringstream text;
    text << "the penalties dominate the final cost (" << last.final_penalty_cost
         << " against the dwells' " << last.final_data_cost << " and the penalty unit "
         << last.penalty_unit
         << "): the enforced jumps and the dwells disagree (check the jump brackets, or relax "
            "the penalties)";
    failure = text.str();
  }
  if (!failure.empty()) {
    summary->status = FitStatus::kFailure;
    summary->converged = false;
    summary->message = failure + "; " + message.str();
    return;
  }
  summary->message = message.str();
}

}  // namespace

FitSummary SolveStaged(const FitDescription& fit, const StagedSolveOptions& options) {
  FitSummary summary;
  std::string error;
  if (!options.IsValid(&error) || !fit.IsValid(&error)) {
    summary.status = FitStatus::kInvalidInput;
    summary.message = error;
    return summary;
  }
  const SolveContext context{fit, options, StartScale(fit, options.residual.form),
                             ResolveThreadCount(options.solver.num_threads)};
  std::vector<double> previous_start;
  bool fold_stage_ran = false;
  bool after_start_stage = false;
  for (size_t s = 0; s < options.stages.size(); ++s) {
    const ResidualKind kind = options.stages[s];
    ChosenStart chosen;
    if (s == 0 && IsBranchLabelled(kind) && options.algebraic_start_candidate) {
      previous_start = fit.Values();
      after_start_stage = RunStartStage(context, kind, &summary);
    }
    if (kind == ResidualKind::kVertical || (s == 0 && after_start_stage)) {
      chosen = ChooseStart(context, {kind, after_start_stage || s > 0 ? &previous_start : nullptr,
                                     s == 0 && after_start_stage, fold_stage_ran});
      if (chosen.fold_stage) {
        summary.stages.push_back(std::move(*chosen.fold_stage));
        fold_stage_ran = true;
      }
      if (!chosen.failure.empty()) return EvaluationFailed(chosen.failure, &summary);
    }
    previous_start = fit.Values();
    // The algebraic stage fits the dwells alone.
    std::vector<PenaltyOptions> runs = {kind == ResidualKind::kAlgebraic ? PenaltyOptions{}
                                                                         : options.penalties};
    const BifurcationRangeOptions& range = options.penalties.bifurcation_range;
    if (kind == ResidualKind::kVertical && range.enabled && range.exponent > 2) {
      // Continuation: u^10 is flat near the bracket and so stiff far from it
      // that Levenberg-Marquardt creeps; u^2 first brings each fold near.
      runs.insert(runs.begin(), options.penalties);
      runs.front().bifurcation_range.exponent = 2;
    }
    // An algebraic stage before the last only starts the next one.
    const bool start_only = kind == ResidualKind::kAlgebraic && s + 1 < options.stages.size();
    for (const PenaltyOptions& penalties : runs) {
      summary.stages.emplace_back();
      summary.stages.back().note = std::exchange(chosen.note, "");
      // The first run solves on the problem its start was rated on.
      if (!RunStage(context, kind, penalties, start_only, &summary.stages.back(), &error,
                    std::move(chosen.rated))) {
        return EvaluationFailed(error, &summary);
      }
    }
  }
  const std::string not_minimum = CheckMinimum(context, &summary, &error);
  if (!error.empty()) return EvaluationFailed(error, &summary);
  Conclude(fit, &summary);
  summary.not_minimum = not_minimum;
  if (!not_minimum.empty() && summary.status == FitStatus::kConverged) {
    summary.status = FitStatus::kNoConvergence;
    summary.converged = false;
    summary.message = "not a minimum: " + not_minimum + "; " + summary.message;
  }
  return summary;
}

}  // namespace dwellfit
