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
// The six parameters live in one 6-double block or in entries of several
// blocks shared between datasets (a ParameterLayout, read through a
// MappedCostFunction). StageProblem sets bounds, fixed entries and scaling.
#ifndef DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_
#define DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_

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
  // covariance's 1/s against the caller's standardised blocks. > 0.
  double dwell_weight = 1.0;
  PenaltyOptions penalties;  // eqs. (3.17) and (3.19), for AddPenalties
};

class ProblemBuilder {
 public:
  // Dwells per batch: enough that Ceres' work per block is small beside
  // theirs, few enough that a sweep's batches spread over the threads.
  static constexpr size_t kDwellsPerBatch = 32;

  // The staged solve has checked the residual options and penalties.
  explicit ProblemBuilder(const ProblemBuilderOptions& options);

  // Adds the residuals of every dwell of `sweep` (two each for kPhaseLag,
  // which throws InputError naming a dwell without a measured phase) on the
  // blocks of `layout` (which must outlive `problem`), in order, up to
  // kDwellsPerBatch consecutive dwells per residual block; through
  // `evaluator` (the problem's evaluation
  // callback) when given. The vertical error's functors are appended to
  // `warm_started`, when given. Returns the number of dwells added.
  int AddSweep(const Sweep& sweep, const ParameterLayout& layout, ceres::Problem* problem,
               ParallelResidualEvaluator* evaluator = nullptr,
               std::vector<VerticalErrorResidual*>* warm_started = nullptr) const;

  // Adds the enabled penalties for `sweep`: a BifurcationRangePenalty per
  // enforced measured jump, a BranchStabilityPenalty per dwell labelled
  // lower or upper. On the algebraic residual the enforced jumps get their
  // unweighted FoldConditionResidual instead, and no branch-stability term.
  void AddPenalties(const Sweep& sweep, const ParameterLayout& layout, ceres::Problem* problem,
                    ParallelResidualEvaluator* evaluator = nullptr) const;

  // The residual blocks AddSweep adds for `sweep`.
  int ResidualBlocks(const Sweep& sweep) const;

  // The cost function of one dwell on one 6-double block, owned by the caller.
  ceres::CostFunction* MakeResidual(const DwellPoint& point) const;

 private:
  // dwell_weight, times 1/sigma of the error where the dwell's sigma is used.
  double AmplitudeWeight(const DwellPoint& point) const;
  // The residual block of dwells [first, end) of `points`: a FunctorBatch
  // (algebraic, vertical) or a BatchedCostFunction of MakeResidual's.
  ceres::CostFunction* MakeBatch(const std::vector<DwellPoint>& points, size_t first, size_t end,
                                 std::vector<VerticalErrorResidual*>* warm_started) const;
  void Add(ceres::CostFunction* cost, const ParameterLayout& layout, ceres::Problem* problem,
           ParallelResidualEvaluator* evaluator) const;
  ModelForm form() const { return options_.residual_options.form; }

  ProblemBuilderOptions options_;
};

// Which enforceable target a measured jump of `sweep` is.
JumpTarget TargetOf(const Sweep& sweep, const JumpBracket& jump);

// Whether `range` (enabled) enforces this measured jump of `sweep`.
bool IsEnforced(const BifurcationRangeOptions& range, const Sweep& sweep, const JumpBracket& jump);

// The bifurcation-range penalty of one measured jump (eq. 3.17; for the
// all-roots residual a RootTransitionPenalty) in `form`, owned by the caller.
ceres::CostFunction* MakeBifurcationRangePenalty(ModelForm form, const Sweep& sweep,
                                                 const JumpBracket& jump,
                                                 const BifurcationRangeOptions& options,
                                                 ResidualKind residual = ResidualKind::kVertical);

// Whether the model at `p` has the fold the jump's bifurcation-range
// penalty measures (within a factor 2 of the bracket).
bool FoldExists(ModelForm form, const Sweep& sweep, const JumpBracket& jump,
                const ParameterVector& p);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_
