#include "dwellfit/estimator/fit/identification.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/fit/bound_rest_watcher.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "glog/logging.h"

namespace dwellfit {

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

bool SolveProblem(const SolverSettings& settings, ceres::Problem* problem,
                  ceres::Solver::Summary* summary) {
  ceres::Solve(MakeSolverOptions(settings), problem, summary);
  return summary->IsSolutionUsable();
}

namespace {

bool PenaltiesEnabled(const PenaltyOptions& penalties) {
  return penalties.bifurcation_range.enabled || penalties.branch_stability.enabled;
}

// Successful steps a parameter sits on its bound before it is held there.
constexpr int kStepsAtBoundBeforeHolding = 5;
// Solves in one stage at the most (see RunStage).
constexpr int kMaxSolvesPerStage = 12;

// One solve's problem on `parameters`: the data of the fitted sweeps, then
// (AddPenalties) the penalties, evaluated on the evaluator's threads.
class StageProblem {
 public:
  StageProblem(const std::vector<const Sweep*>& fitted, const ProblemBuilderOptions& options,
               int num_threads, ParameterVector* parameters)
      : builder_(options),
        parameters_(parameters),
        evaluator_(parameters->data(), kNumParameters, num_threads),
        problem_(ProblemOptions(&evaluator_)) {
    for (const Sweep* sweep : fitted) {
      blocks_ += builder_.AddSweep(*sweep, parameters->data(), &problem_, &evaluator_);
      for (const DwellPoint& point : sweep->points) dwells_.push_back({sweep, &point});
    }
    CHECK_GT(blocks_, 0) << "no dwell points to fit";
    problem_.GetResidualBlocks(&data_blocks_);
    CHECK_EQ(data_blocks_.size(), dwells_.size()) << "one residual block per dwell";
  }

  // Adds the penalties of `options` (weights in the caller's units).
  void AddPenalties(const std::vector<const Sweep*>& fitted, const PenaltyOptions& options) {
    ProblemBuilderOptions penalty_options = builder_.options();
    penalty_options.penalties = options;
    const ProblemBuilder penalty_builder(penalty_options);
    for (const Sweep* sweep : fitted) {
      penalty_builder.AddPenalties(*sweep, parameters_->data(), &problem_, &evaluator_);
    }
  }

  // The cost of the data residuals alone (no penalties) at the current values.
  double DataCost() {
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.residual_blocks = data_blocks_;
    double cost = 0.0;
    problem_.Evaluate(evaluate, &cost, nullptr, nullptr, nullptr);
    return cost;
  }

  // The gradient of the whole cost in the physical parameters.
  bool CostGradient(std::vector<double>* gradient) {
    return evaluator_.CostGradient(parameters_->data(), gradient);
  }

  ceres::Solver::Summary Solve(const SolverSettings& settings) {
    builder_.ConfigureParameters(parameters_->data(), &problem_);
    std::vector<BoundRestWatcher::Bound> bounds;
    for (int i : {kEtaE, kMu1, kMu2}) {
      const bool bounded = i == kEtaE || builder_.options().bound_damping;
      if (bounded && !builder_.options().fixed[i]) bounds.push_back({i, 0.0});
    }
    BoundRestWatcher watcher(parameters_->data(), bounds, kStepsAtBoundBeforeHolding);
    ceres::Solver::Options options = MakeSolverOptions(settings);
    if (builder_.options().residual == ResidualKind::kVertical) {
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
    ceres::Solve(options, &problem_, &summary);
    resting_ = watcher.resting();
    return summary;
  }

  // The bounded parameter that stopped the last Solve by resting on its bound.
  std::optional<int> resting() const { return resting_; }
  int blocks() const { return blocks_; }

  // Why a solve that `summary` reports as failed could not evaluate its
  // cost: the dwells (or penalties) whose residual or Jacobian is not finite
  // at the current values, or else Ceres' message.
  std::string DescribeFailure(const ceres::Solver::Summary& summary) {
    std::vector<ceres::ResidualBlockId> blocks;
    problem_.GetResidualBlocks(&blocks);
    int bad_dwells = 0;
    int first_bad = -1;
    bool bad_penalty = false;
    for (std::size_t i = 0; i < blocks.size(); ++i) {
      if (EvaluatesFinite(blocks[i])) continue;
      if (i >= dwells_.size()) {
        bad_penalty = true;
      } else if (bad_dwells++ == 0) {
        first_bad = static_cast<int>(i);
      }
    }
    if (first_bad < 0) {
      return bad_penalty ? "a penalty term is not finite there (penalties, config/README.md)"
                         : "Ceres: " + summary.message;
    }
    const auto [sweep, point] = dwells_[first_bad];
    std::ostringstream text;
    text << (bad_dwells == static_cast<int>(dwells_.size())
                 ? "no dwell's residual is finite there, so the parameters are at fault (the "
                   "first dwell: "
                 : std::to_string(bad_dwells) + " dwell(s) have a residual that is not finite " +
                       "there (the first: ")
         << sweep->source_file << ":" << point->source_line << ", sweep " << sweep->Name() << ", "
         << RadPerSecondToHz(point->drive_frequency_rad_s) << " Hz, a_base " << point->a_base
         << ", a " << point->amplitude << ")";
    return text.str();
  }

 private:
  // Whether the block evaluates, with finite residuals and Jacobian.
  bool EvaluatesFinite(ceres::ResidualBlockId block) {
    const ceres::CostFunction* cost = problem_.GetCostFunctionForResidualBlock(block);
    std::vector<double> residuals(cost->num_residuals());
    std::vector<double> jacobian(cost->num_residuals() * kNumParameters);
    double* jacobians[] = {jacobian.data()};
    const double* point[] = {parameters_->data()};
    if (!cost->Evaluate(point, residuals.data(), jacobians)) return false;
    bool finite = true;
    for (double r : residuals) finite = finite && std::isfinite(r);
    for (double j : jacobian) finite = finite && std::isfinite(j);
    return finite;
  }

  static ceres::Problem::Options ProblemOptions(ParallelResidualEvaluator* evaluator) {
    ceres::Problem::Options options;
    options.evaluation_callback = evaluator;
    return options;
  }

  const ProblemBuilder builder_;
  ParameterVector* const parameters_;
  ParallelResidualEvaluator evaluator_;  // outlives problem_, which calls it
  ceres::Problem problem_;
  std::vector<ceres::ResidualBlockId> data_blocks_;
  // The sweep and dwell of each data block, in the order of data_blocks_.
  std::vector<std::pair<const Sweep*, const DwellPoint*>> dwells_;
  int blocks_ = 0;
  std::optional<int> resting_;
};

// The parameter scale of a stage: the user's start, not where an earlier
// stage landed, so that a stage that drove a parameter to its bound still
// steps sensibly.
ParameterVector StartScale(const ParameterVector& initial) {
  ParameterVector scale;
  for (int i = 0; i < kNumParameters; ++i) {
    scale[i] = std::abs(initial[i]) > 0.0 ? std::abs(initial[i]) : 1.0;
  }
  return scale;
}

// "eta_e 130, mu1 0.14, ..., omega 251.327 rad/s".
std::string DescribeParameters(const ParameterVector& parameters) {
  std::ostringstream text;
  for (int i = 0; i < kNumParameters; ++i) {
    text << (i > 0 ? ", " : "") << ParameterName(i) << " " << parameters[i];
  }
  text << " rad/s";
  return text.str();
}

// Releases, once each, the held parameters whose cost gradient points into
// the feasible side (the cost falls as they leave their bound: d cost / d p_i
// < 0 at p_i = 0). True when one was released.
bool ReleaseHeld(StageProblem* problem, std::array<bool, kNumParameters>* held,
                 std::array<bool, kNumParameters>* released) {
  std::vector<double> gradient;
  if (!problem->CostGradient(&gradient)) return false;
  bool released_any = false;
  for (int i = 0; i < kNumParameters; ++i) {
    if ((*held)[i] && !(*released)[i] && gradient[i] < 0.0) {
      (*held)[i] = false;
      (*released)[i] = true;
      released_any = true;
    }
  }
  return released_any;
}

// One stage: the residual `kind` (with `penalties` on a vertical stage) from
// `*parameters`, which it updates.
//
// Active set: a bounded parameter that rests on its bound is held there
// (BoundRestWatcher) and the stage solves again without it; when that solve
// ends, a held parameter whose cost gradient points into the feasible side
// (the cost falls as it leaves its bound) is released, once, and the stage
// solves again. A solve that ends on a convergence test with nothing to
// release ends the stage. A solve that cannot evaluate its cost (Ceres'
// FAILURE, or a cost that is not finite) ends it with `failure` set.
StageSummary RunStage(const std::vector<const Sweep*>& fitted, const IdentificationOptions& options,
                      ResidualKind kind, const PenaltyOptions& penalties,
                      ParameterVector* parameters) {
  ProblemBuilderOptions builder_options;
  builder_options.residual = kind;
  builder_options.residual_options = options.residual;
  builder_options.scale = StartScale(options.initial);
  builder_options.bound_damping = kind != ResidualKind::kAlgebraic;
  const int threads = ResolveThreadCount(options.solver.num_threads);
  const bool with_penalties = kind == ResidualKind::kVertical && PenaltiesEnabled(penalties);

  StageSummary stage;
  stage.residual = kind;
  std::array<bool, kNumParameters> held{};
  std::array<bool, kNumParameters> released{};
  PenaltyOptions weighted = penalties;
  for (int round = 0;; ++round) {
    for (int i = 0; i < kNumParameters; ++i) builder_options.fixed[i] = options.fixed[i] || held[i];
    StageProblem problem(fitted, builder_options, threads, parameters);
    if (round == 0 && with_penalties) {
      // The penalties are weighed in the data's own units, taken where the
      // stage starts: a few bifurcation-range terms against the data's sum
      // of squared residuals, one branch-stability term per dwell against
      // the mean squared residual of a dwell.
      stage.penalty_unit = 2.0 * problem.DataCost();
      stage.penalty_exponent =
          penalties.bifurcation_range.enabled ? penalties.bifurcation_range.exponent : 0;
      weighted.bifurcation_range.weight *= stage.penalty_unit;
      weighted.branch_stability.weight *= stage.penalty_unit / problem.blocks();
    }
    if (with_penalties) problem.AddPenalties(fitted, weighted);
    stage.residual_blocks = problem.blocks();

    const ParameterVector start = *parameters;
    const ceres::Solver::Summary summary = problem.Solve(options.solver);
    VLOG(2) << ResidualKindName(kind) << " stage, solve " << round + 1 << ": "
            << summary.BriefReport();
    if (round == 0) stage.initial_cost = summary.initial_cost;
    stage.final_cost = summary.final_cost;
    stage.iterations += std::max(static_cast<int>(summary.iterations.size()) - 1, 0);
    ++stage.solves;
    stage.converged = summary.termination_type == ceres::CONVERGENCE;
    stage.brief_report = summary.BriefReport();
    if (!summary.IsSolutionUsable() || !std::isfinite(summary.final_cost)) {
      stage.converged = false;
      stage.failure = std::string("the ") + ResidualKindName(kind) +
                      " stage cannot evaluate its cost at " + DescribeParameters(start) + ": " +
                      problem.DescribeFailure(summary);
      break;
    }
    stage.final_data_cost = problem.DataCost();
    // Each of the three bounded parameters is held at most twice and
    // released at most once, so this bound is never reached in practice.
    if (round + 1 >= kMaxSolvesPerStage) break;
    if (problem.resting()) {
      held[*problem.resting()] = true;
      VLOG(1) << ResidualKindName(kind) << " stage: holding " << ParameterName(*problem.resting())
              << " at its bound";
      continue;
    }
    if (!ReleaseHeld(&problem, &held, &released)) break;
  }
  for (int i = 0; i < kNumParameters; ++i) {
    if (held[i]) stage.held_at_bound.push_back(i);
  }
  if (!builder_options.bound_damping && ReflectDampingIntoPhysicalRange(parameters)) {
    VLOG(1) << "reflected the " << ResidualKindName(kind) << " stage's damping";
  }
  stage.parameters = *parameters;
  VLOG(1) << ResidualKindName(kind) << " stage: " << stage.brief_report;
  return stage;
}

}  // namespace

IdentificationResult Identify(const std::vector<const Sweep*>& fitted,
                              const IdentificationOptions& options) {
  std::string error;
  CHECK(options.IsValid(&error)) << error;
  IdentificationResult result;
  result.parameters = options.initial;
  for (ResidualKind kind : options.stages) {
    const BifurcationRangeOptions& range = options.penalties.bifurcation_range;
    if (kind == ResidualKind::kVertical && range.enabled && range.exponent > 2) {
      // Continuation: u^n with n = 10 is flat near the bracket and so stiff
      // far from it that Levenberg-Marquardt creeps; the quadratic penalty
      // first brings each fold near its bracket, then the configured one holds it.
      PenaltyOptions quadratic = options.penalties;
      quadratic.bifurcation_range.exponent = 2;
      result.stages.push_back(RunStage(fitted, options, kind, quadratic, &result.parameters));
      if (!result.stages.back().failure.empty()) break;
    }
    result.stages.push_back(RunStage(fitted, options, kind, options.penalties, &result.parameters));
    if (!result.stages.back().failure.empty()) break;
  }
  for (const StageSummary& stage : result.stages)
    result.iterations += std::max(stage.iterations, 0);
  result.residual_blocks = result.stages.back().residual_blocks;
  result.final_cost = result.stages.back().final_cost;
  result.converged = result.stages.back().converged;
  result.failure = result.stages.back().failure;
  return result;
}

}  // namespace dwellfit
