// BatchedCostFunction: several cost functions on the same parameter blocks,
// stacked into one residual block.
//
// r = [r_1; ...; r_m] and each block's Jacobian stack the members' rows, so
// Ceres' work per residual block is paid once per batch, not per dwell. The
// cost (1/2) sum_i |r_i|^2 is the members' sum; no loss function may be
// attached (it would act on the sum). Evaluate fails when any member fails.
#ifndef DWELLFIT_ESTIMATOR_FIT_BATCHED_COST_FUNCTION_H_
#define DWELLFIT_ESTIMATOR_FIT_BATCHED_COST_FUNCTION_H_

#include <algorithm>
#include <array>
#include <deque>
#include <memory>
#include <utility>
#include <vector>

#include "ceres/cost_function.h"
#include "ceres/internal/autodiff.h"
#include "ceres/internal/parameter_dims.h"
#include "ceres/jet.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/response_model.h"

namespace dwellfit {

class BatchedCostFunction : public ceres::CostFunction {
 public:
  // Takes ownership of `members` (at least one), which must all read
  // parameter blocks of the same sizes, in the same order.
  explicit BatchedCostFunction(std::vector<ceres::CostFunction*> members);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::vector<std::unique_ptr<ceres::CostFunction>> members_;
  std::vector<int> first_row_;  // of each member in the batch
};

// FunctorBatch: the same for functors whose cost function would be an
// AutoDiffCostFunction<Functor, 1, kNumParameters> each, held side by side.
// The parameters' terms (ParameterTerms) are formed once per batch, on Jets
// seeded as AutoDifferentiate seeds them, so each member's residual and
// Jacobian row are the numbers AutoDiffCostFunction gives. The terms are
// formed in the batch's model form, which must be its members' form.
template <typename Functor>
class FunctorBatch : public ceres::CostFunction {
 public:
  explicit FunctorBatch(ModelForm form) : form_(form) {
    mutable_parameter_block_sizes()->push_back(kNumParameters);
  }

  // Appends a member made from `args` (Functor's constructor arguments) and
  // returns it; it lives as long as the batch, at this address.
  template <typename... Args>
  Functor* Add(Args&&... args) {
    functors_.emplace_back(std::forward<Args>(args)...);
    set_num_residuals(static_cast<int>(functors_.size()));
    return &functors_.back();
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (jacobians == nullptr) {
      const ParameterTerms<double> terms(form_, parameters[0]);
      for (size_t m = 0; m < functors_.size(); ++m) {
        if (!functors_[m].Evaluate(terms, residuals + m)) return false;
      }
      return true;
    }
    using Dims = ceres::internal::StaticParameterDims<kNumParameters>;
    using JetT = ceres::Jet<double, kNumParameters>;
    std::array<JetT, kNumParameters> point;
    ceres::internal::Make1stOrderPerturbations<Dims::Parameters>::Apply(parameters, point.data());
    const ParameterTerms<JetT> terms(form_, point.data());
    for (size_t m = 0; m < functors_.size(); ++m) {
      JetT residual;
      residual.a = ceres::kImpossibleValue;
      residual.v.setConstant(ceres::kImpossibleValue);
      if (!functors_[m].Evaluate(terms, &residual)) return false;
      residuals[m] = residual.a;
      if (jacobians[0] != nullptr) {
        std::copy(residual.v.data(), residual.v.data() + kNumParameters,
                  jacobians[0] + m * kNumParameters);
      }
    }
    return true;
  }

 private:
  const ModelForm form_;
  // A deque: members keep their address as more are added, and need not be
  // movable.
  std::deque<Functor> functors_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_BATCHED_COST_FUNCTION_H_
