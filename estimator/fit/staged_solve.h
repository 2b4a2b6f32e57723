// The staged solve: the multi-stage fit of the chapter's final algorithm
// (section 3.2.4) on any FitDescription (fit_description.h), the library's
// one way to solve an identification problem. Identify (identification.h)
// is its single-dataset case.
//
// Stages run in order on the caller's blocks, each starting where the
// previous ended. The default is [algebraic, vertical]: the algebraic
// residual of eq. (3.11) is smooth and branch-free and so lands near the
// minimum from a rough start; the vertical error, which respects branches
// and stability, then converges from there. Every stage assembles its own
// ceres::Problem (StageProblem, stage_problem.h): the dwells of every
// dataset, the enabled penalties on a vertical stage, then the caller's own
// residual blocks (FitDescription::add_residuals).
//
// Penalties join every vertical stage, their weights in units of the data's
// mean squared residual at the stage's start: inside a bracket a penalty
// costs about as much as one dwell's misfit, outside it grows as u^n or
// exponentially, so it constrains without overriding what the data
// determine. With an exponent n > 2 each vertical stage runs first with
// n = 2 (continuation), then with n.
//
// A vertical stage starts from the better of where the previous stage
// started and ended (fewer enforced folds missing, then a lower cost of the
// dwells): the algebraic residual knows no branches, and its minimum may
// lack a fold the vertical stage must place. When that start still lacks an
// enforced fold, a fold stage runs first: the algebraic residual with each
// enforced jump's fold conditions (FoldConditionResidual, smooth where the
// bifurcation-range penalty has no fold to measure), and the better of its
// start and end is taken. The summary's stages say which (note, fold_stage).
//
// The last stage decides the status: converged or not; a failure when it
// ends without an enforced fold, with the penalties' cost above both the
// dwells' cost and the penalty unit (the enforced jumps and the dwells
// disagree), or at values that are not finite.
//
// A run whose first stage is branch-labelled (vertical or all_roots) starts
// with a start stage: the algebraic residual from the given start. The first
// stage then starts from the better of the given start and the start stage's
// end, rated as above with the stage's own residual, and its note records
// which and why. Off with algebraic_start_candidate = false.
//
// Within a stage the bounds (eta_e, mu1, mu2 >= 0) are an active set: an
// entry resting on its bound is held there (BoundRestWatcher) and the stage
// solves again without it; a held entry whose cost gradient points into the
// feasible side is released, once. A vertical or all-roots solve that
// creeps along a weakly determined direction is finished by the valley
// polish (valley_polish.h), at most twice a stage. The algebraic stage runs
// with the damping unbounded and reflects its result into the physical range
// (ReflectDampingIntoPhysicalRange). Results do not depend on
// `solver.num_threads`.
//
// Never aborts on bad input: invalid options or description give
// FitStatus::kInvalidInput with a message naming the field, and leave the
// blocks untouched.
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
  kFailure,         // not usable: a stage's solve failed (the model could not be
                    // evaluated; the blocks hold where that solve stopped), or the fit
                    // ended without an enforced fold, with a cost dominated by the
                    // penalties, or with values that are not finite
  kInvalidInput,    // invalid options or description: nothing solved, blocks untouched
  kUnidentifiable,  // set by the analysis (not SolveStaged): the solve ended, but the
                    // data cannot tell the free parameters apart (no covariance)
};
const char* FitStatusName(FitStatus status);  // "converged", "no_convergence", ...

struct StageSummary {
  ResidualKind residual = ResidualKind::kVertical;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  // final_cost of the dwells alone (no penalties, no caller residual blocks).
  double final_data_cost = 0.0;
  // Penalty weights multiply this: the mean squared data residual where the
  // stage started (0 when the stage had no penalties).
  double penalty_unit = 0.0;
  int penalty_exponent = 0;  // n of eq. (3.17) in this stage (0: none)
  // The penalties this stage minimised, with the weights it used (in the
  // cost's own units: the configured weights times penalty_unit, and for
  // the branch-stability penalty divided by the dwells), exponents and
  // enforced jumps: what the analysis of the fit reads (profile_likelihood.h).
  PenaltyOptions penalties;
  int residual_blocks = 0;  // dwell points fitted
  int iterations = 0;       // over the stage's solves and valley polishes
  int solves = 0;           // one, and one more per bound held or released and per valley polish
  bool converged = false;   // its last solve met a convergence test
  // Bounded entries the stage ended holding on their bound (an active set),
  // as ambient indices of the description (for Identify: ParameterIndex).
  std::vector<int> held_at_bound;
  // Penalties' cost at the end (0 without penalties) and the enforced jumps
  // whose fold the model lacks there (StageProblem::MissingFolds).
  double final_penalty_cost = 0.0;
  std::vector<std::string> missing_folds;
  // An algebraic stage with the enforced jumps' fold conditions
  // (FoldConditionResidual), run before a vertical stage whose start lacks
  // an enforced fold.
  bool fold_stage = false;
  // The algebraic stage run from the given start before a first stage that
  // is branch-labelled (StagedSolveOptions::algebraic_start_candidate): its
  // end is a candidate start for that stage.
  bool start_stage = false;
  // Why the stage ran or where it started, when that is not the plain
  // sequence: a start or fold stage, a first branch-labelled stage's choice
  // between the given start and the start stage's end, or a vertical stage
  // that started where the previous stage started (ChooseStart in the .cc).
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
  // Why the point the fit ended at is not a minimum of its cost (the
  // minimum check: a step along some entry lowers the cost; status then
  // kNoConvergence), "" when the check passed.
  std::string not_minimum;
  // kFailure because a stage's solve could not evaluate its cost (the later
  // stages did not run): the values are where that solve stopped, no fit.
  bool evaluation_failed = false;

  // The blocks hold a solution (converged, or stopped at the iteration limit;
  // not a unique one when unidentifiable).
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
// physical twin: eta_e -> |eta_e|, (mu1, mu2) -> -(mu1, mu2) when neither is
// positive; a damping left negative after that (mixed signs: no physical
// twin) is set to 0. Returns whether anything changed.
bool ReflectDampingIntoPhysicalRange(ParameterVector* parameters);

// The same on the entries of a description: every eta_e entry to its
// magnitude; every damping entry (mu1 or mu2 of some dataset) negated when
// none is positive (the whole fit's twin), then clamped at 0. Entries are
// listed once each.
bool ReflectDampingIntoPhysicalRange(const std::vector<double*>& eta_e_entries,
                                     const std::vector<double*>& damping_entries);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_STAGED_SOLVE_H_
