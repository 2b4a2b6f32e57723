// BatchedCostFunction: several cost functions on the same parameter blocks,
// stacked into one residual block.
//
// The residuals are the members' residuals in order, r = [r_1; r_2; ...; r_m],
// and so is each parameter block's Jacobian (row-major, the members' rows
// stacked). Ceres' work per residual block (bookkeeping, the Jacobian's
// projection onto the manifold, the validity checks) is then paid once per
// batch instead of once per dwell, which on thousands of one-row dwell blocks
// was about a third of a fit's time. Each member keeps its own definition: for
// a dwell the autodiff VerticalErrorResidual with its Newton root solve.
//
// The cost of a batch is (1/2) sum_i |r_i|^2, the sum of its members' costs;
// no loss function may be attached to a batch (it would act on the sum).
// Evaluate fails when any member fails.
#ifndef DWELLFIT_ESTIMATOR_FIT_BATCHED_COST_FUNCTION_H_
#define DWELLFIT_ESTIMATOR_FIT_BATCHED_COST_FUNCTION_H_

#include <memory>
#include <vector>

#include "ceres/cost_function.h"

namespace dwellfit {

class BatchedCostFunction : public ceres::CostFunction {
 public:
  // Takes ownership of `members` (at least one), which must all read
  // parameter blocks of the same sizes, in the same order.
  explicit BatchedCostFunction(std::vector<ceres::CostFunction*> members);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  int num_members() const { return static_cast<int>(members_.size()); }

 private:
  std::vector<std::unique_ptr<ceres::CostFunction>> members_;
  std::vector<int> first_row_;  // of each member in the batch
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_BATCHED_COST_FUNCTION_H_
