// ProblemBuilder: the residual blocks of the identification problem, added to
// a ceres::Problem on parameter blocks the caller owns.
//
// Mathematical formulation. With p = [eta_e, mu1, mu2, delta, alpha, omega]
// (model_parameters.h) and the dwell points i of the chosen sweeps,
//
//   minimise over the free entries of p   (1/2) sum_i r_i(p)^2
//   subject to                            eta_e, mu1, mu2 >= 0
//
// where r_i is either the algebraic residual of eq. (3.11)
// (residuals/functors/algebraic_residual.h) or the vertical error of section
// 3.2.4 (residuals/functors/vertical_error_residual.h).
//
// The six parameters may live in one 6-double block (the residual blocks
// then read it directly) or in entries of several blocks, shared between
// datasets (a ParameterLayout, fit_description.h; the residual blocks then
// read those blocks through a MappedCostFunction). Bounds, fixed entries and
// scaling are set by StageProblem (stage_problem.h), which assembles every
// problem the staged solve and the covariance use.
#ifndef DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_
#define DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_

#include <string>
#include <vector>

#include "ceres/problem.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

struct ProblemBuilderOptions {
  ResidualKind residual = ResidualKind::kVertical;
  ResidualOptions residual_options;
  // Multiplies every dwell's residual (on top of its point sigma): the
  // covariance weighs the dwells by 1/s, s the residual noise, against the
  // caller's standardised residual blocks. > 0.
  double dwell_weight = 1.0;
  // Soft constraints of eqs. (3.17) and (3.19); AddPenalties adds them.
  PenaltyOptions penalties;
  // AddSweep puts up to ProblemBuilder::kDwellsPerBatch consecutive dwells in
  // one residual block (FunctorBatch, BatchedCostFunction) instead of one
  // block per dwell.
  bool batch_dwells = false;
  bool IsValid(std::string* error) const;
};

class ProblemBuilder {
 public:
  // Dwells per residual block with `batch_dwells`: enough that Ceres' work
  // per block is small beside the dwells', few enough that a sweep's batches
  // spread over the threads.
  static constexpr size_t kDwellsPerBatch = 32;

  // `options` should be valid (IsValid); the staged solve checks them.
  explicit ProblemBuilder(const ProblemBuilderOptions& options);

  // Adds the residuals of every dwell of `sweep` (one each, two for
  // kPhaseLag, which throws InputError naming the dwell when one has no
  // measured phase), each reading the six parameters where `layout` puts
  // them (the blocks are owned by the caller and must outlive `problem`):
  // one residual block per dwell, in order, or with `batch_dwells` up to
  // kDwellsPerBatch consecutive dwells per residual block. With an
  // `evaluator` (the problem's evaluation callback, watching the layout's
  // blocks) the blocks are evaluated through it, on its threads. With
  // `warm_started`, the vertical error's functors (whose root solves start
  // where the last ended) are appended to it. Returns the number of dwells
  // added.
  int AddSweep(const Sweep& sweep, const ParameterLayout& layout, ceres::Problem* problem,
               ParallelResidualEvaluator* evaluator = nullptr,
               std::vector<VerticalErrorResidual*>* warm_started = nullptr) const;
  // The same on one 6-double block `parameters` (SingleBlockLayout).
  int AddSweep(const Sweep& sweep, double* parameters, ceres::Problem* problem,
               ParallelResidualEvaluator* evaluator = nullptr) const;

  // Adds the enabled penalties for `sweep`: one BifurcationRangePenalty per
  // measured jump whose target is enforced, one BranchStabilityPenalty per
  // dwell labelled lower or upper. On the algebraic residual the enforced
  // jumps get their FoldConditionResidual instead (the algebraic form of
  // eq. 3.17; the weights of `penalties` are not used) and there is no
  // branch-stability term. Returns the number of blocks added.
  int AddPenalties(const Sweep& sweep, const ParameterLayout& layout, ceres::Problem* problem,
                   ParallelResidualEvaluator* evaluator = nullptr) const;
  int AddPenalties(const Sweep& sweep, double* parameters, ceres::Problem* problem,
                   ParallelResidualEvaluator* evaluator = nullptr) const;

  // The residual blocks AddSweep adds for `sweep`: one per dwell, or with
  // `batch_dwells` one per kDwellsPerBatch dwells begun.
  int ResidualBlocks(const Sweep& sweep) const;

  // The cost function of one dwell on one 6-double block (owned by the
  // caller; Ceres takes it); a vertical error's functor is appended to
  // `warm_started`, when given.
  ceres::CostFunction* MakeResidual(
      const DwellPoint& point, std::vector<VerticalErrorResidual*>* warm_started = nullptr) const;

  const ProblemBuilderOptions& options() const { return options_; }

 private:
  // The weight of a dwell's amplitude error: dwell_weight, and 1/sigma of the
  // error measured where the dwell carries its sigma and it is used.
  double AmplitudeWeight(const DwellPoint& point) const;
  // The residual block of dwells [first, end) of `points` (batch_dwells):
  // the algebraic and the vertical error as a FunctorBatch, any other
  // residual as a BatchedCostFunction of MakeResidual's cost functions.
  ceres::CostFunction* MakeBatch(const std::vector<DwellPoint>& points, size_t first, size_t end,
                                 std::vector<VerticalErrorResidual*>* warm_started) const;
  // Adds `cost` (on one 6-double block) as a residual block on `layout`.
  void Add(ceres::CostFunction* cost, const ParameterLayout& layout, ceres::Problem* problem,
           ParallelResidualEvaluator* evaluator) const;

  ProblemBuilderOptions options_;
};

// Which enforceable target a measured jump of `sweep` is.
JumpTarget TargetOf(const Sweep& sweep, const JumpBracket& jump);

// Whether `range` (enabled) enforces this measured jump of `sweep`.
bool IsEnforced(const BifurcationRangeOptions& range, const Sweep& sweep, const JumpBracket& jump);

// The bifurcation-range penalty of one measured jump (eq. 3.17; for the
// all-roots residual, RootTransitionPenalty: the range enforced through the
// roots), owned by the caller; Ceres takes it.
ceres::CostFunction* MakeBifurcationRangePenalty(const Sweep& sweep, const JumpBracket& jump,
                                                 const BifurcationRangeOptions& options,
                                                 ResidualKind residual = ResidualKind::kVertical);

// Whether the model at `p` has the fold of `jump` (the fold the
// bifurcation-range penalty measures, within a factor 2 of the bracket).
bool FoldExists(const Sweep& sweep, const JumpBracket& jump, const ParameterVector& p);

// The algebraic fold condition of one measured jump (FoldConditionResidual),
// weighted by the square root of its sweep's dwell count; owned by the
// caller.
ceres::CostFunction* MakeFoldCondition(const Sweep& sweep, const JumpBracket& jump);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_
