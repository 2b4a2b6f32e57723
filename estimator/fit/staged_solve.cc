#include "dwellfit/estimator/fit/staged_solve.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/fit/bound_rest_watcher.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/fit/stage_problem.h"
#include "glog/logging.h"

namespace dwellfit {

const char* FitStatusName(FitStatus status) {
  switch (status) {
    case FitStatus::kConverged:
      return "converged";
    case FitStatus::kNoConvergence:
      return "no_convergence";
    case FitStatus::kFailure:
      return "failure";
    case FitStatus::kInvalidInput:
      return "invalid_input";
  }
  return "invalid_input";
}

ceres::Solver::Options MakeSolverOptions(const SolverSettings& settings) {
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = settings.max_iterations;
  options.function_tolerance = settings.function_tolerance;
  options.gradient_tolerance = settings.gradient_tolerance;
  options.parameter_tolerance = settings.parameter_tolerance;
  // One thread: the residual blocks are evaluated on threads, in a fixed
  // order, by ParallelResidualEvaluator (ceres' own threads sum in an order
  // that varies between runs).
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
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

bool ReflectDampingIntoPhysicalRange(ParameterVector* parameters) {
  ParameterVector& p = *parameters;
  return ReflectDampingIntoPhysicalRange({&p[kEtaE]}, {&p[kMu1], &p[kMu2]});
}

namespace {

bool PenaltiesEnabled(const PenaltyOptions& penalties) {
  return penalties.bifurcation_range.enabled || penalties.branch_stability.enabled;
}

// Successful steps an entry sits on its bound before it is held there.
constexpr int kStepsAtBoundBeforeHolding = 5;
// Solves in one stage at the most (see RunStage).
constexpr int kMaxSolvesPerStage = 12;

// The stage-independent part of a staged solve.
struct SolveContext {
  const FitDescription& fit;
  const StagedSolveOptions& options;
  std::vector<double> scale;  // per ambient entry
  int threads = 1;
};

// One solve of `problem`, with the active set's watcher; `*resting` is the
// entry that stopped it by resting on its bound.
ceres::Solver::Summary SolveOnce(ResidualKind kind, const SolverSettings& settings,
                                 StageProblem* problem, std::optional<int>* resting) {
  problem->Configure();
  BoundRestWatcher watcher(problem->WatchedBounds(), kStepsAtBoundBeforeHolding);
  ceres::Solver::Options options = MakeSolverOptions(settings);
  if (kind == ResidualKind::kVertical || kind == ResidualKind::kAllRoots) {
    // No projected line search. With bounds set (eta_e, mu1, mu2 >= 0)
    // Ceres runs an Armijo search along every trust-region step; on the
    // vertical error, whose gradient spans some twenty decades (root
    // solves, folds, penalties), its polynomial interpolation now and then
    // cuts a good step to nothing, which ends the solve on the function
    // tolerance far from a minimum (on the measured beam: in a basin of
    // ten times the cost). The bounds are still enforced: Ceres projects
    // the step onto them. The algebraic stage keeps the search: from a
    // rough start its full steps overshoot by orders of magnitude and the
    // backtracking rescues them.
    options.max_num_line_search_step_size_iterations = 0;
  }
  options.callbacks.push_back(&watcher);
  options.update_state_every_iteration = true;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem->problem(), &summary);
  *resting = watcher.resting();
  return summary;
}

// Releases, once each, the held entries whose cost gradient points into the
// feasible side (the cost falls as they leave their bound: d cost / d p < 0
// at p = 0). Returns whether any was released.
bool ReleaseHeld(StageProblem* problem, std::vector<bool>* held, std::vector<bool>* released) {
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

// Weighs the penalties in the data's own units, taken where the stage
// starts: a few bifurcation-range terms against the data's sum of squared
// residuals, one branch-stability term per dwell against the mean squared
// residual of a dwell.
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

// The entries of `fit` holding eta_e of some dataset, or with `damping` its
// mu1 or mu2, each once.
std::vector<double*> EntriesHolding(const FitDescription& fit, bool damping) {
  std::vector<bool> holding = fit.EntriesHolding(damping ? kMu1 : kEtaE);
  if (damping) {
    const std::vector<bool> mu2 = fit.EntriesHolding(kMu2);
    for (size_t i = 0; i < holding.size(); ++i) holding[i] = holding[i] || mu2[i];
  }
  std::vector<double*> entries;
  for (size_t b = 0; b < fit.blocks.size(); ++b) {
    for (int i = 0; i < fit.blocks[b].size; ++i) {
      if (holding[fit.Offset(static_cast<int>(b)) + i]) entries.push_back(fit.blocks[b].values + i);
    }
  }
  return entries;
}

void RecordSolve(const ceres::Solver::Summary& summary, int round, StageProblem* problem,
                 StageSummary* stage) {
  if (round == 0) stage->initial_cost = summary.initial_cost;
  stage->final_cost = summary.final_cost;
  stage->iterations += std::max(static_cast<int>(summary.iterations.size()) - 1, 0);
  ++stage->solves;
  stage->converged = summary.termination_type == ceres::CONVERGENCE;
  stage->brief_report = summary.BriefReport();
  stage->final_data_cost = problem->DataCost();
}

// "eta_e 100, mu1 0.2, ..., omega 251.3 rad/s": every entry of `fit` at
// `values`, natural frequencies with their unit.
std::string DescribeValues(const FitDescription& fit, const std::vector<double>& values) {
  const std::vector<bool> natural_frequency = fit.EntriesHolding(kNaturalFrequency);
  std::ostringstream text;
  for (size_t i = 0; i < values.size(); ++i) {
    text << (i > 0 ? ", " : "") << fit.EntryName(static_cast<int>(i)) << " " << values[i]
         << (natural_frequency[i] ? " rad/s" : "");
  }
  return text.str();
}

// One stage: the residual `kind` (with `penalties` on a vertical stage) from
// the blocks' values, which it updates. False when a solve failed
// (`*failure` says why).
//
// Active set: a bounded entry that rests on its bound is held there
// (BoundRestWatcher) and the stage solves again without it; when that solve
// ends, a held entry whose cost gradient points into the feasible side is
// released, once, and the stage solves again. A solve that ends on a
// convergence test with nothing to release ends the stage.
bool RunStage(const SolveContext& context, ResidualKind kind, const PenaltyOptions& penalties,
              StageSummary* stage, std::string* failure) {
  StageSetup setup;
  setup.residuals.residual = kind;
  setup.residuals.residual_options = context.options.residual;
  setup.scale = context.scale;
  setup.bound_damping = kind != ResidualKind::kAlgebraic;
  setup.num_threads = context.threads;
  // The all-roots stage takes the penalties too, its range through the roots.
  const bool with_penalties =
      (kind == ResidualKind::kVertical || kind == ResidualKind::kAllRoots) &&
      PenaltiesEnabled(penalties);
  const int entries = context.fit.NumEntries();
  setup.held.assign(entries, false);
  std::vector<bool> released(entries, false);
  stage->residual = kind;
  PenaltyOptions weighted = penalties;
  for (int round = 0;; ++round) {
    StageProblem problem(context.fit, setup);
    if (round == 0 && with_penalties) weighted = WeighPenalties(penalties, &problem, stage);
    if (with_penalties) problem.AddPenalties(weighted);
    problem.AddCallerResiduals();
    stage->residual_blocks = problem.dwells();
    std::optional<int> resting;
    const std::vector<double> start = context.fit.Values();
    const ceres::Solver::Summary summary =
        SolveOnce(kind, context.options.solver, &problem, &resting);
    VLOG(2) << ResidualKindName(kind) << " stage, solve " << round + 1 << ": "
            << summary.BriefReport();
    RecordSolve(summary, round, &problem, stage);
    if (!summary.IsSolutionUsable() || !std::isfinite(summary.final_cost)) {
      stage->converged = false;
      *failure = std::string("the ") + ResidualKindName(kind) +
                 " stage cannot evaluate its cost at " + DescribeValues(context.fit, start) + ": " +
                 problem.DescribeFailure(summary.message);
      return false;
    }
    // Each bounded entry is held at most twice and released at most once,
    // so this bound is never reached in practice.
    if (round + 1 >= kMaxSolvesPerStage) break;
    if (resting) {
      setup.held[*resting] = true;
      VLOG(1) << ResidualKindName(kind) << " stage: holding " << context.fit.EntryName(*resting)
              << " at its bound";
      continue;
    }
    if (!ReleaseHeld(&problem, &setup.held, &released)) break;
  }
  for (int i = 0; i < entries; ++i) {
    if (setup.held[i]) stage->held_at_bound.push_back(i);
  }
  if (!setup.bound_damping && ReflectDampingIntoPhysicalRange(EntriesHolding(context.fit, false),
                                                              EntriesHolding(context.fit, true))) {
    VLOG(1) << "reflected the " << ResidualKindName(kind) << " stage's damping";
  }
  stage->values = context.fit.Values();
  VLOG(1) << ResidualKindName(kind) << " stage: " << stage->brief_report;
  return true;
}

// The step unit of every entry: its scale when given, else the magnitude of
// its value at the start (1 for 0), so that a stage that drove an entry to
// its bound still steps sensibly.
std::vector<double> StartScale(const FitDescription& fit) {
  std::vector<double> scale;
  for (const FitBlock& block : fit.blocks) {
    for (int i = 0; i < block.size; ++i) {
      const double magnitude = std::abs(block.values[i]);
      scale.push_back(!block.scale.empty() ? block.scale[i] : magnitude > 0.0 ? magnitude : 1.0);
    }
  }
  return scale;
}

// Status and message from how the last stage ended.
void Conclude(FitSummary* summary) {
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
  const SolveContext context{fit, options, StartScale(fit),
                             ResolveThreadCount(options.solver.num_threads)};
  for (ResidualKind kind : options.stages) {
    std::vector<PenaltyOptions> runs = {options.penalties};
    const BifurcationRangeOptions& range = options.penalties.bifurcation_range;
    if (kind == ResidualKind::kVertical && range.enabled && range.exponent > 2) {
      // Continuation: u^n with n = 10 is flat near the bracket and so stiff
      // far from it that Levenberg-Marquardt creeps; the quadratic penalty
      // first brings each fold near its bracket, then the configured one
      // holds it.
      runs.insert(runs.begin(), options.penalties);
      runs.front().bifurcation_range.exponent = 2;
    }
    for (const PenaltyOptions& penalties : runs) {
      summary.stages.emplace_back();
      if (!RunStage(context, kind, penalties, &summary.stages.back(), &error)) {
        summary.status = FitStatus::kFailure;
        summary.message = error;
        summary.final_cost = summary.stages.back().final_cost;
        return summary;
      }
    }
  }
  Conclude(&summary);
  return summary;
}

}  // namespace dwellfit
