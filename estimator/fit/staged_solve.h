// The staged solve: the multi-stage fit of the chapter's final algorithm
// (section 3.2.4) on any FitDescription (fit_description.h). Identify
// (identification.h) is its single-dataset case.
//
// Stages run in order, each from where the previous ended, each on its own
// ceres::Problem (StageProblem): the dwells, on a vertical stage the enabled
// penalties, then the caller's residual blocks. The default [algebraic,
// vertical]: the smooth, branch-free algebraic residual of eq. (3.11) lands
// near the minimum from a rough start; the vertical error, which respects
// branches and stability, converges from there.
//
// Penalty weights are in units of the data's mean squared residual at the
// stage's start: inside a bracket a penalty costs about one dwell's misfit.
// With an exponent n > 2 each vertical stage runs first with n = 2.
//
// A vertical stage starts from the better of where the previous stage
// started and ended (fewer enforced folds missing, then a lower cost of the
// dwells): the algebraic minimum may lack a fold. When that start still
// lacks an enforced fold, a fold stage (the algebraic residual with the
// fold conditions, FoldConditionResidual) runs first, and the better of its
// start and end is taken. A run whose first stage is branch-labelled
// (vertical or all_roots) starts with a start stage, the algebraic residual
// from the given start, and that stage starts from the better of the two
// (off with algebraic_start_candidate = false). Notes record each choice.
//
// Within a stage the bounds (eta_e, mu1, mu2 >= 0) are an active set: an
// entry resting on its bound is held there (BoundRestWatcher) and the stage
// solves again; a held entry whose cost gradient points into the feasible
// side is released, once. A vertical or all-roots solve that creeps is
// finished by the valley polish (valley_polish.h), at most twice a stage.
// The algebraic stage leaves the damping unbounded and reflects its result
// (ReflectDampingIntoPhysicalRange). A final minimum check steps along each
// free entry. Results do not depend on `solver.num_threads`.
//
// The last stage decides the status: a failure when it ends without an
// enforced fold, with the penalties' cost above both the dwells' cost and
// the penalty unit, or at values that are not finite. Invalid options or
// description give kInvalidInput with a message naming the field, blocks
// untouched.
#ifndef DWELLFIT_ESTIMATOR_FIT_STAGED_SOLVE_H_
#define DWELLFIT_ESTIMATOR_FIT_STAGED_SOLVE_H_

#include <string>
#include <vector>

#include "ceres/solver.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/identification_options.h"

namespace dwellfit {

// How a staged solve ended (like ceres::TerminationType).
enum class FitStatus {
  kConverged,       // the last stage met a convergence test
  kNoConvergence,   // the last stage stopped at its iteration limit: usable, not a proven minimum
  kFailure,         // not usable: a solve could not evaluate the model, or the fit ended
                    // in a failure the header lists
  kInvalidInput,    // invalid options or description: nothing solved, blocks untouched
  kUnidentifiable,  // set by the analysis: the data cannot tell the free parameters apart
};
const char* FitStatusName(FitStatus status);  // "converged", "no_convergence", ...

struct StageSummary {
  ResidualKind residual = ResidualKind::kVertical;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double final_data_cost = 0.0;  // of the dwells alone
  // Penalty weights multiply this: the mean squared data residual where the
  // stage started (0 without penalties).
  double penalty_unit = 0.0;
  int penalty_exponent = 0;  // n of eq. (3.17) in this stage (0: none)
  // The penalties this stage minimised, with the weights it used (the
  // configured ones times penalty_unit, the branch-stability one divided by
  // the dwells), for the analysis (profile_likelihood.h).
  PenaltyOptions penalties;
  int residual_blocks = 0;  // dwell points fitted
  int iterations = 0;       // over the stage's solves and valley polishes
  int solves = 0;           // one, and one more per bound held or released and per valley polish
  bool converged = false;   // its last solve met a convergence test
  // Entries the stage ended holding on their bound, as ambient indices.
  std::vector<int> held_at_bound;
  // Penalties' cost at the end and the enforced jumps whose fold the model
  // lacks there (StageProblem::MissingFolds).
  double final_penalty_cost = 0.0;
  std::vector<std::string> missing_folds;
  bool fold_stage = false;   // a fold stage (above)
  bool start_stage = false;  // a start stage (above)
  // Why the stage ran or where it started, when that is not the plain
  // sequence (a start or fold stage, a choice of start, a valley polish).
  std::string note;
  std::string brief_report;    // ceres::Solver::Summary::BriefReport() of its last solve
  std::vector<double> values;  // every entry where the stage ended, ambient order
};

struct FitSummary {
  FitStatus status = FitStatus::kInvalidInput;
  std::string message;  // plain words: what ended the solve, or what is wrong with the input
  std::vector<StageSummary> stages;
  int residual_blocks = 0;  // dwell points fitted
  double final_cost = 0.0;  // of the last stage
  int iterations = 0;       // over all stages
  bool converged = false;   // status == kConverged
  // Why the end is not a minimum (a step along some entry lowers the cost;
  // status then kNoConvergence), "" when the minimum check passed.
  std::string not_minimum;
  // kFailure because a solve could not evaluate its cost: the values are
  // where it stopped, no fit.
  bool evaluation_failed = false;

  // The blocks hold a solution (not a unique one when unidentifiable).
  bool IsSolutionUsable() const {
    return status == FitStatus::kConverged || status == FitStatus::kNoConvergence ||
           status == FitStatus::kUnidentifiable;
  }
};

// The Levenberg-Marquardt options every stage starts from.
ceres::Solver::Options MakeSolverOptions(const SolverSettings& settings);

// Runs the stages of `options` on `fit`, updating the caller's blocks.
FitSummary SolveStaged(const FitDescription& fit, const StagedSolveOptions& options);

// G(a) of eq. (3.11) depends on mu1, mu2 only through k1^2, k2^2 and k1 k2,
// and on eta_e only through 1/eta_e^2. Maps a point fitted on G alone to its
// physical twin: eta_e -> |eta_e|, (mu1, mu2) -> -(mu1, mu2) when none is
// positive, then a negative damping (no twin) to 0, on a description's eta_e
// and damping (mu1, mu2) entries, each listed once. Returns whether anything
// changed.
bool ReflectDampingIntoPhysicalRange(const std::vector<double*>& eta_e_entries,
                                     const std::vector<double*>& damping_entries);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_STAGED_SOLVE_H_
