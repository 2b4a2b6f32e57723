#include "dwellfit/estimator/fit/mapped_cost_function.h"

#include <algorithm>

#include "ceres/internal/fixed_array.h"
#include "glog/logging.h"

namespace dwellfit {

namespace {

// Residuals of a wrapped function whose Jacobian fits on the stack (every
// dwellfit functor has one; more go on the heap).
constexpr int kStackResiduals = 4;

}  // namespace

MappedCostFunction::MappedCostFunction(ceres::CostFunction* model_cost,
                                       const ParameterLayout& layout)
    : model_cost_(model_cost), layout_(layout) {
  CHECK_EQ(model_cost->parameter_block_sizes().size(), 1u);
  CHECK_EQ(model_cost->parameter_block_sizes()[0], kNumParameters);
  set_num_residuals(model_cost->num_residuals());
  *mutable_parameter_block_sizes() = layout.sizes;
}

bool MappedCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  double values[kNumParameters];
  for (int i = 0; i < kNumParameters; ++i) {
    values[i] = parameters[layout_.block[i]][layout_.index[i]];
  }
  const double* model_blocks[] = {values};
  if (jacobians == nullptr) return model_cost_->Evaluate(model_blocks, residuals, nullptr);

  const int rows = num_residuals();
  ceres::internal::FixedArray<double, kStackResiduals * kNumParameters> model_jacobian(
      rows * kNumParameters);
  double* model_jacobians[] = {model_jacobian.data()};
  if (!model_cost_->Evaluate(model_blocks, residuals, model_jacobians)) return false;

  for (size_t b = 0; b < layout_.blocks.size(); ++b) {
    if (jacobians[b] != nullptr) {
      std::fill(jacobians[b], jacobians[b] + rows * layout_.sizes[b], 0.0);
    }
  }
  for (int i = 0; i < kNumParameters; ++i) {
    double* jacobian = jacobians[layout_.block[i]];
    if (jacobian == nullptr) continue;
    const int size = layout_.sizes[layout_.block[i]];
    for (int row = 0; row < rows; ++row) {
      jacobian[row * size + layout_.index[i]] += model_jacobian[row * kNumParameters + i];
    }
  }
  return true;
}

}  // namespace dwellfit
