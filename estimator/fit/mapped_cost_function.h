// MappedCostFunction: a cost function of the six model parameters (one
// 6-double block, as every dwellfit functor reads), evaluated on parameters
// that live in entries of the caller's blocks (fit_description.h).
//
// Evaluate gathers p_i = blocks[layout.block[i]][layout.index[i]], evaluates
// the wrapped function at p, and scatters dr/dp onto the blocks:
// dr/d(block b, entry e) = sum of dr/dp_i over the p_i that live in (b, e).
#ifndef DWELLFIT_ESTIMATOR_FIT_MAPPED_COST_FUNCTION_H_
#define DWELLFIT_ESTIMATOR_FIT_MAPPED_COST_FUNCTION_H_

#include <memory>

#include "ceres/cost_function.h"
#include "dwellfit/estimator/fit/fit_description.h"

namespace dwellfit {

class MappedCostFunction : public ceres::CostFunction {
 public:
  // Takes ownership of `model_cost` (one block of kNumParameters); the
  // residual block's parameter blocks are `layout.blocks`.
  MappedCostFunction(ceres::CostFunction* model_cost, const ParameterLayout& layout);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const std::unique_ptr<ceres::CostFunction> model_cost_;
  const ParameterLayout layout_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_MAPPED_COST_FUNCTION_H_
