// StageProblem: the one place a ceres::Problem is assembled from a
// FitDescription, for every solve of SolveStaged and the covariance.
//
// In order: every described block; the dwells of every dataset in batches
// (ProblemBuilder::AddSweep), through a ParallelResidualEvaluator and
// compressed into one block unless !threaded_evaluation; when asked,
// the penalties and the caller's residual blocks; last the bounds, fixed
// and held entries and scaling (Configure).
#ifndef DWELLFIT_ESTIMATOR_FIT_STAGE_PROBLEM_H_
#define DWELLFIT_ESTIMATOR_FIT_STAGE_PROBLEM_H_

#include <functional>
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
  // The dwells' residual (its `penalties` unused: AddPenalties takes them).
  ProblemBuilderOptions residuals;
  std::vector<double> scale;  // per ambient entry: the change of one step unit
  bool bound_damping = true;  // mu1, mu2 >= 0 (eta_e >= 0 always)
  // Evaluate the dwells and penalties through the ParallelResidualEvaluator
  // on `num_threads` (>= 1) threads, the solver seeing the dwells as one
  // block (ParallelResidualEvaluator::Compress) and their own blocks
  // (dwell_blocks) in a problem of their own; false: Ceres evaluates each
  // block itself (the covariance, which evaluates twice).
  bool threaded_evaluation = true;
  int num_threads = 1;
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
  // Per ambient entry: held in addition to the fixed entries (empty: none),
  // from the next Configure on.
  void Hold(const std::vector<bool>& held);
  // The next evaluation gives the values a problem just assembled would:
  // every block evaluated anew, root solves from the measured amplitudes.
  void EvaluateAfresh();

  // Costs at the blocks' current values (infinity where some block cannot
  // be evaluated): the dwells alone, the penalties (0 without), and all.
  double DataCost();
  double PenaltyCost();
  double TotalCost();
  // The enforced jumps of `range` (when enabled) where the model at the
  // current values has no fold of the jump's kind, each named: "L0.060g/up:
  // no jump_down fold near its measured bracket 180.924..180.953 Hz".
  std::vector<std::string> MissingFolds(const BifurcationRangeOptions& range) const;
  // The gradient of the whole cost in the described entries (ambient order)
  // at their current values: no manifold, bounds or held entries. False if a
  // residual block cannot be evaluated.
  bool CostGradient(std::vector<double>* gradient);
  // The bounded entries neither fixed nor held, for a BoundRestWatcher (id:
  // the ambient index), with where the solver's iterate holds them (none
  // without threaded evaluation). Valid after Configure.
  std::vector<BoundRestWatcher::Entry> WatchedBounds() const;
  // Sets the blocks to the solver's last iterate (threaded evaluation only).
  void MoveToIterate();

  // The problem a solve solves (with compressed dwells: their one block).
  ceres::Problem* problem() { return &problem_; }
  // The problem holding dwell_blocks().
  ceres::Problem* dwell_problem() {
    return setup_.threaded_evaluation ? &dwell_problem_ : &problem_;
  }
  int dwells() const { return dwells_; }
  // Why a solve could not evaluate its cost: the dwells (or penalties) not
  // finite at the current values, named by file, line and sweep, or else
  // `ceres_message`.
  std::string DescribeFailure(const std::string& ceres_message);
  // The dwells' residual blocks in dwell order (batches), in dwell_problem().
  const std::vector<ceres::ResidualBlockId>& dwell_blocks() const { return dwell_blocks_; }
  const std::vector<ceres::ResidualBlockId>& caller_blocks() const { return caller_blocks_; }

 private:
  static ceres::Problem::Options ProblemOptions(ParallelResidualEvaluator* evaluator);
  // Runs `add`, then owns the cost functions of the blocks it added to
  // `problem` (each once when `may_share`: a caller's may serve several
  // blocks), even when it throws; returns those blocks.
  std::vector<ceres::ResidualBlockId> AddOwned(ceres::Problem* problem, bool may_share,
                                               const std::function<void()>& add);
  void AddDwells();
  static std::vector<ParallelResidualEvaluator::Block> EvaluatedBlocks(const FitDescription& fit);
  ParallelResidualEvaluator* Evaluator() {
    return setup_.threaded_evaluation ? &evaluator_ : nullptr;
  }
  bool IsBounded(int entry) const;  // lower bound 0
  bool IsHeld(int entry) const;

  const FitDescription& fit_;
  const StageSetup setup_;
  std::vector<bool> held_;           // see Hold
  std::vector<bool> held_constant_;  // per block: set constant by Configure
  const ProblemBuilder builder_;
  std::vector<ParameterLayout> layouts_;  // per dataset
  std::vector<bool> eta_e_entries_;       // per ambient entry
  std::vector<bool> damping_entries_;
  std::vector<bool> fixed_;
  // Every cost function (not owned by the problem: Ceres then keeps no map
  // entry per cost function). Destroyed after problem_.
  std::vector<std::unique_ptr<const ceres::CostFunction>> cost_functions_;
  ParallelResidualEvaluator evaluator_;  // outlives the problems, which call it
  ceres::Problem problem_;
  // The dwells' own blocks when compressed (no evaluation callback).
  ceres::Problem dwell_problem_;
  std::vector<ceres::ResidualBlockId> dwell_blocks_;
  std::vector<ceres::ResidualBlockId> caller_blocks_;
  std::vector<ceres::ResidualBlockId> penalty_blocks_;
  // The dwells' vertical-error functors, whose root solves start warm.
  std::vector<VerticalErrorResidual*> warm_started_;
  int dwells_ = 0;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_STAGE_PROBLEM_H_
