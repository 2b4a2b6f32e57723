// Identification: the default multi-stage fit of the chapter's final
// algorithm (section 3.2.4) on a set of fitted sweeps.
//
// Stages run in order on the same parameter block, each starting where the
// previous ended. Enabled penalties join every vertical stage, their weights
// in units of the data's mean squared residual at the stage's start: inside a
// bracket a penalty costs about as much as one dwell's misfit, outside it
// grows as u^n or exponentially, so it constrains without overriding what the
// data determine (on exact data it vanishes). The default is [algebraic, vertical]: the algebraic
// residual of eq. (3.11) is smooth and branch-free and so lands near the minimum from a rough
// start; the vertical error, which respects branches and stability, then converges from there.
// Within a stage the bounds eta_e, mu1, mu2 >= 0 are an active set: a parameter resting on its
// bound is held there, and released if the cost falls as it leaves (RunStage in the .cc).
#ifndef DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_H_
#define DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_H_

#include <string>
#include <vector>

#include "ceres/problem.h"
#include "ceres/solver.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

struct StageSummary {
  ResidualKind residual = ResidualKind::kVertical;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double final_data_cost = 0.0;  // final_cost less the penalties
  // Penalty weights multiply this: the mean squared data residual where the
  // stage started (0 when the stage had no penalties).
  double penalty_unit = 0.0;
  int penalty_exponent = 0;  // n of eq. (3.17) in this stage (0: none)
  int residual_blocks = 0;   // dwell points fitted
  int iterations = 0;        // over the stage's solves
  int solves = 0;            // one, and one more per bound held or released
  bool converged = false;    // its last solve met a convergence test
  // Bounded parameters the stage ended holding on their bound (an active
  // set: see RunStage in identification.cc), ParameterIndex values.
  std::vector<int> held_at_bound;
  std::string brief_report;  // ceres::Solver::Summary::BriefReport() of its last solve
  // Why the stage could not solve: its cost could not be evaluated or was
  // not finite (names the parameters and the first dwell at fault); "" when
  // it solved. The stages after a failed one do not run.
  std::string failure;
  ParameterVector parameters;  // where the stage ended
};

struct IdentificationResult {
  ParameterVector parameters;  // physical units, omega in rad/s
  std::vector<StageSummary> stages;
  int residual_blocks = 0;  // dwell points fitted
  double final_cost = 0.0;  // of the last stage
  int iterations = 0;       // over all stages
  bool converged = false;   // the last stage converged
  // The failure of the stage that stopped the fit ("" when every stage
  // solved): the result is then no estimate and must not be reported as one.
  std::string failure;
};

ceres::Solver::Options MakeSolverOptions(const SolverSettings& settings);

// Solves a problem assembled by ProblemBuilder. Returns whether the solution is
// usable (ceres::Solver::Summary::IsSolutionUsable).
bool SolveProblem(const SolverSettings& settings, ceres::Problem* problem,
                  ceres::Solver::Summary* summary);

// Runs the configured stages on `fitted` from options.initial.
IdentificationResult Identify(const std::vector<const Sweep*>& fitted,
                              const IdentificationOptions& options);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_H_
