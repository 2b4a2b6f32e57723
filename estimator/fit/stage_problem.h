// StageProblem: the one place a ceres::Problem is assembled from a
// FitDescription. Every solve of every stage of SolveStaged (staged_solve.h)
// and the covariance (estimator/analysis/block_covariance.h) build theirs
// here.
//
// In order: every described block; the dwells of every dataset in batches
// (ProblemBuilder::AddSweep), evaluated through a ParallelResidualEvaluator
// unless !threaded_evaluation, and then seen by the solver as one compressed
// block (compress_dwells); when asked, the penalties (AddPenalties) and the
// caller's residual blocks (AddCallerResiduals); last the entries' bounds,
// fixed and held entries and scaling (Configure; fit_description.h).
#ifndef DWELLFIT_ESTIMATOR_FIT_STAGE_PROBLEM_H_
#define DWELLFIT_ESTIMATOR_FIT_STAGE_PROBLEM_H_

#include <memory>
#include <string>
#include <vector>

#include "ceres/problem.h"
#include "dwellfit/estimator/fit/bound_rest_watcher.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"

namespace dwellfit {

struct StageSetup {
  // The dwells' residual (ProblemBuilderOptions::penalties is not used:
  // AddPenalties takes them).
  ProblemBuilderOptions residuals;
  // Per ambient entry: the physical change of one solver step unit.
  std::vector<double> scale;
  // Per ambient entry: held at its value in addition to the fixed entries
  // (empty: none).
  std::vector<bool> held;
  bool bound_damping = true;  // mu1, mu2 >= 0 (eta_e >= 0 always)
  // Evaluate the dwells and penalties through the ParallelResidualEvaluator
  // on `num_threads` (>= 1) threads; false: Ceres evaluates every residual
  // block itself, each time it asks (the covariance, which evaluates twice).
  bool threaded_evaluation = true;
  int num_threads = 1;
  // With threaded_evaluation: the solver sees the dwells as one residual
  // block of a few rows (ParallelResidualEvaluator::Compress), the same
  // cost, gradient and Gauss-Newton matrix; the dwells' own blocks
  // (dwell_blocks) live in a problem of their own, for their values.
  bool compress_dwells = true;
};

class StageProblem {
 public:
  // Adds the blocks and the dwells. `fit` must be valid and outlive this.
  StageProblem(const FitDescription& fit, const StageSetup& setup);

  // Adds `penalties` (weights in the cost's own units) for every sweep.
  void AddPenalties(const PenaltyOptions& penalties);
  // Calls FitDescription::add_residuals, when set.
  void AddCallerResiduals();
  // Bounds, fixed and held entries, scaling. Call after the residuals; again
  // after Hold, to solve once more on the same residual blocks.
  void Configure();
  // Per ambient entry: held at its value in addition to the fixed entries
  // (empty: none), in place of StageSetup::held from the next Configure on.
  void Hold(const std::vector<bool>& held);
  // The next evaluation gives every value a problem just assembled would
  // give at that point: each residual block is evaluated anew, the vertical
  // error's root solves from the measured amplitudes (ForgetRoot).
  void EvaluateAfresh();

  // The cost of the dwells alone at the blocks' current values (infinity
  // where some dwell cannot be evaluated).
  double DataCost();
  // The cost of the penalties added by AddPenalties (0 without them).
  double PenaltyCost();
  // The whole cost at the blocks' current values: the dwells, the penalties
  // and the caller's residual blocks (infinity where some block cannot be
  // evaluated).
  double TotalCost();
  // The enforced jumps of `range` (an enabled bifurcation-range penalty)
  // where the model at the blocks' current values has no fold of the
  // jump's kind, each named: "L0.060g/up: no jump_down fold near its
  // measured bracket 180.924..180.953 Hz". Empty when every enforced fold
  // exists (or the penalty is off).
  std::vector<std::string> MissingFolds(const BifurcationRangeOptions& range) const;
  // The gradient of the whole cost (every residual block, the caller's
  // included) in the described entries, ambient order, at their current
  // values: no manifold, no bounds, no held entries. False if a residual
  // block cannot be evaluated.
  bool CostGradient(std::vector<double>* gradient);
  // The bounded entries that are neither fixed nor held, for a
  // BoundRestWatcher (id: the ambient index), with where the solver's
  // current iterate holds them (ParallelResidualEvaluator::IterateEntry;
  // none without threaded evaluation). Valid after Configure.
  std::vector<BoundRestWatcher::Entry> WatchedBounds() const;
  // Sets the described blocks to the solver's last iterate (see
  // WatchedBounds). Nothing without threaded evaluation.
  void MoveToIterate();

  // The problem a solve solves: with compressed dwells it holds the one
  // block that stands for them, not the dwells' own.
  ceres::Problem* problem() { return &problem_; }
  // The problem holding dwell_blocks(): problem() unless the dwells are
  // compressed.
  ceres::Problem* dwell_problem() { return Compressed() ? &dwell_problem_ : &problem_; }
  int dwells() const { return dwells_; }
  // Why a solve could not evaluate its cost: the dwells (or penalties) whose
  // residual or Jacobian is not finite at the blocks' current values, named
  // by file, line and sweep, or else `ceres_message`.
  std::string DescribeFailure(const std::string& ceres_message);
  // The dwells' residual blocks, in dwell order: batches of consecutive
  // dwells (ProblemBuilderOptions::batch_dwells), in dwell_problem().
  const std::vector<ceres::ResidualBlockId>& dwell_blocks() const { return dwell_blocks_; }
  // The caller's residual blocks (after AddCallerResiduals).
  const std::vector<ceres::ResidualBlockId>& caller_blocks() const { return caller_blocks_; }

 private:
  // Whether the residual block evaluates, with finite residuals and Jacobian.
  bool EvaluatesFinite(ceres::ResidualBlockId block);
  // The same for `cost` on `blocks`.
  static bool EvaluatesFinite(const ceres::CostFunction& cost, const std::vector<double*>& blocks);
  // The six parameters where `layout` reads them.
  static ParameterVector ValuesOf(const ParameterLayout& layout);

  static ceres::Problem::Options ProblemOptions(ParallelResidualEvaluator* evaluator,
                                                bool threaded);
  // Takes ownership of the cost functions of `blocks` from `first` on; each
  // once when `may_share` (a caller's cost function may serve several
  // blocks), else each block's own.
  void OwnCostFunctions(const ceres::Problem& problem,
                        const std::vector<ceres::ResidualBlockId>& blocks, size_t first,
                        bool may_share);
  // Adds every dataset's dwells to dwell_problem() (AddSweep).
  void AddDwells();
  static std::vector<ParallelResidualEvaluator::Block> EvaluatedBlocks(const FitDescription& fit);
  // The evaluator the dwells and penalties go through, or none.
  ParallelResidualEvaluator* Evaluator() {
    return setup_.threaded_evaluation ? &evaluator_ : nullptr;
  }
  bool Compressed() const { return setup_.threaded_evaluation && setup_.compress_dwells; }
  // Whether an entry has the lower bound 0.
  bool IsBounded(int entry) const;
  bool IsHeld(int entry) const;

  const FitDescription& fit_;
  const StageSetup setup_;
  std::vector<bool> held_;  // per ambient entry (empty: none); see Hold
  // Per block: set constant by Configure (every entry fixed or held).
  std::vector<bool> held_constant_;
  const ProblemBuilder builder_;
  std::vector<ParameterLayout> layouts_;  // per dataset
  std::vector<bool> eta_e_entries_;       // per ambient entry
  std::vector<bool> damping_entries_;
  std::vector<bool> fixed_;
  // Every residual block's cost function (the problem does not own them, so
  // Ceres keeps no map entry per cost function). Destroyed after problem_.
  std::vector<std::unique_ptr<const ceres::CostFunction>> cost_functions_;
  ParallelResidualEvaluator evaluator_;  // outlives the problems, which call it
  ceres::Problem problem_;
  // The dwells' own blocks when compressed (no evaluation callback: the
  // caller prepares the evaluator before evaluating them).
  ceres::Problem dwell_problem_;
  std::vector<ceres::ResidualBlockId> dwell_blocks_;
  std::vector<ceres::ResidualBlockId> caller_blocks_;
  std::vector<ceres::ResidualBlockId> penalty_blocks_;
  // The dwells' vertical-error functors (owned by their cost functions),
  // whose root solves start where their last ended.
  std::vector<VerticalErrorResidual*> warm_started_;
  int dwells_ = 0;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_STAGE_PROBLEM_H_
