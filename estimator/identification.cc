#include "estimator/identification.h"

#include <algorithm>
#include <cmath>

#include "estimator/problem_builder.h"
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
  options.num_threads = settings.num_threads;
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

// The cost of the data residuals alone (no penalties) at the current values.
double DataCost(const std::vector<ceres::ResidualBlockId>& data_blocks, ceres::Problem* problem) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.residual_blocks = data_blocks;
  double cost = 0.0;
  problem->Evaluate(evaluate, &cost, nullptr, nullptr, nullptr);
  return cost;
}

// One solve of one residual kind (with `penalties` on a vertical stage) from
// `*parameters`, which it updates.
StageSummary RunStage(const std::vector<const Sweep*>& fitted, const IdentificationOptions& options,
                      ResidualKind kind, const PenaltyOptions& penalties,
                      ParameterVector* parameters) {
  ProblemBuilderOptions builder_options;
  builder_options.residual = kind;
  builder_options.residual_options = options.residual;
  builder_options.fixed = options.fixed;
  // Scale from the user's start, not from where an earlier stage landed, so
  // that a stage that drove a parameter to its bound still steps sensibly.
  ParameterVector scale;
  for (int i = 0; i < kNumParameters; ++i) {
    scale[i] = std::abs(options.initial[i]) > 0.0 ? std::abs(options.initial[i]) : 1.0;
  }
  builder_options.scale = scale;
  builder_options.bound_damping = kind != ResidualKind::kAlgebraic;
  const ProblemBuilder builder(builder_options);

  ceres::Problem problem;
  int blocks = 0;
  for (const Sweep* sweep : fitted)
    blocks += builder.AddSweep(*sweep, parameters->data(), &problem);
  CHECK_GT(blocks, 0) << "no dwell points to fit";
  std::vector<ceres::ResidualBlockId> data_blocks;
  problem.GetResidualBlocks(&data_blocks);
  StageSummary stage;
  stage.residual = kind;
  if (kind == ResidualKind::kVertical && PenaltiesEnabled(penalties)) {
    // The penalties are weighed in the data's own units, taken where the
    // stage starts: a few bifurcation-range terms against the data's sum of
    // squared residuals, one branch-stability term per dwell against the
    // mean squared residual of a dwell.
    stage.penalty_unit = 2.0 * DataCost(data_blocks, &problem);
    stage.penalty_exponent =
        penalties.bifurcation_range.enabled ? penalties.bifurcation_range.exponent : 0;
    ProblemBuilderOptions penalty_options = builder_options;
    penalty_options.penalties = penalties;
    penalty_options.penalties.bifurcation_range.weight *= stage.penalty_unit;
    penalty_options.penalties.branch_stability.weight *= stage.penalty_unit / blocks;
    const ProblemBuilder penalty_builder(penalty_options);
    for (const Sweep* sweep : fitted) {
      penalty_builder.AddPenalties(*sweep, parameters->data(), &problem);
    }
  }
  builder.ConfigureParameters(parameters->data(), &problem);

  ceres::Solver::Summary summary;
  SolveProblem(options.solver, &problem, &summary);
  if (!builder_options.bound_damping && ReflectDampingIntoPhysicalRange(parameters)) {
    VLOG(1) << "reflected the " << ResidualKindName(kind) << " stage's damping";
  }
  stage.final_data_cost = DataCost(data_blocks, &problem);
  stage.initial_cost = summary.initial_cost;
  stage.final_cost = summary.final_cost;
  stage.iterations = static_cast<int>(summary.iterations.size()) - 1;
  stage.converged = summary.termination_type == ceres::CONVERGENCE;
  stage.brief_report = summary.BriefReport();
  stage.parameters = *parameters;
  stage.residual_blocks = blocks;
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
    }
    result.stages.push_back(RunStage(fitted, options, kind, options.penalties, &result.parameters));
  }
  for (const StageSummary& stage : result.stages)
    result.iterations += std::max(stage.iterations, 0);
  result.residual_blocks = result.stages.back().residual_blocks;
  result.final_cost = result.stages.back().final_cost;
  result.converged = result.stages.back().converged;
  return result;
}

}  // namespace dwellfit
