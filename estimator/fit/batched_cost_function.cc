#include "dwellfit/estimator/fit/batched_cost_function.h"

#include <array>

#include "glog/logging.h"

namespace dwellfit {

namespace {

// Parameter blocks whose Jacobian pointers fit on the stack (every dwellfit
// residual reads at most six).
constexpr size_t kStackBlocks = 8;

}  // namespace

BatchedCostFunction::BatchedCostFunction(std::vector<ceres::CostFunction*> members) {
  CHECK(!members.empty());
  *mutable_parameter_block_sizes() = members.front()->parameter_block_sizes();
  CHECK_LE(parameter_block_sizes().size(), kStackBlocks);
  int rows = 0;
  for (ceres::CostFunction* member : members) {
    CHECK(member->parameter_block_sizes() == parameter_block_sizes());
    members_.emplace_back(member);
    first_row_.push_back(rows);
    rows += member->num_residuals();
  }
  set_num_residuals(rows);
}

bool BatchedCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  std::array<double*, kStackBlocks> member_jacobians{};
  for (size_t m = 0; m < members_.size(); ++m) {
    const int row = first_row_[m];
    if (jacobians != nullptr) {
      for (size_t j = 0; j < sizes.size(); ++j) {
        member_jacobians[j] = jacobians[j] == nullptr ? nullptr : jacobians[j] + row * sizes[j];
      }
    }
    if (!members_[m]->Evaluate(parameters, residuals + row,
                               jacobians == nullptr ? nullptr : member_jacobians.data())) {
      return false;
    }
  }
  return true;
}

}  // namespace dwellfit
