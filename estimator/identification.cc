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
  return options;
}

bool SolveProblem(const SolverSettings& settings, ceres::Problem* problem,
                  ceres::Solver::Summary* summary) {
  ceres::Solve(MakeSolverOptions(settings), problem, summary);
  return summary->IsSolutionUsable();
}

IdentificationResult Identify(const std::vector<const Sweep*>& fitted,
                              const IdentificationOptions& options) {
  std::string error;
  CHECK(options.IsValid(&error)) << error;
  IdentificationResult result;
  result.parameters = options.initial;
  for (ResidualKind kind : options.stages) {
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
      blocks += builder.AddSweep(*sweep, result.parameters.data(), &problem);
    CHECK_GT(blocks, 0) << "no dwell points to fit";
    builder.ConfigureParameters(result.parameters.data(), &problem);

    ceres::Solver::Summary summary;
    SolveProblem(options.solver, &problem, &summary);
    if (!builder_options.bound_damping && ReflectDampingIntoPhysicalRange(&result.parameters)) {
      VLOG(1) << "reflected the " << ResidualKindName(kind) << " stage's damping";
    }
    StageSummary stage;
    stage.residual = kind;
    stage.initial_cost = summary.initial_cost;
    stage.final_cost = summary.final_cost;
    stage.iterations = static_cast<int>(summary.iterations.size()) - 1;
    stage.converged = summary.termination_type == ceres::CONVERGENCE;
    stage.brief_report = summary.BriefReport();
    stage.parameters = result.parameters;
    VLOG(1) << ResidualKindName(kind) << " stage: " << stage.brief_report;
    result.stages.push_back(stage);
    result.residual_blocks = blocks;
    result.iterations += std::max(stage.iterations, 0);
  }
  result.final_cost = result.stages.back().final_cost;
  result.converged = result.stages.back().converged;
  return result;
}

}  // namespace dwellfit
