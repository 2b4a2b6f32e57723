#include "dwellfit/estimator/fit/batched_cost_function.h"

#include <memory>
#include <vector>

#include "ceres/autodiff_cost_function.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// r = [c x0 + y0^2 ; c y1 - x0 y0], on blocks x (1 value) and y (2 values);
// fails to evaluate where x0 < c (a member that cannot be evaluated there).
struct TwoRows {
  explicit TwoRows(double c) : c(c) {}
  template <typename T>
  bool operator()(const T* x, const T* y, T* r) const {
    if (x[0] < T(c)) return false;
    r[0] = c * x[0] + y[0] * y[0];
    r[1] = c * y[1] - x[0] * y[0];
    return true;
  }
  double c;
};

ceres::CostFunction* NewTwoRows(double c) {
  return new ceres::AutoDiffCostFunction<TwoRows, 2, 1, 2>(new TwoRows(c));
}

// Each member's residuals and Jacobians, evaluated on its own, stacked.
void EvaluateMembersAlone(const std::vector<double>& constants, const double* const* blocks,
                          std::vector<double>* residuals, std::vector<double>* dx,
                          std::vector<double>* dy) {
  for (double c : constants) {
    const std::unique_ptr<ceres::CostFunction> member(NewTwoRows(c));
    double r[2], jx[2], jy[4];
    double* jacobians[] = {jx, jy};
    ASSERT_TRUE(member->Evaluate(blocks, r, jacobians));
    residuals->insert(residuals->end(), r, r + 2);
    dx->insert(dx->end(), jx, jx + 2);
    dy->insert(dy->end(), jy, jy + 4);
  }
}

TEST(BatchedCostFunction, StacksItsMembersResidualsAndJacobians) {
  const std::vector<double> constants = {0.5, -1.5, 2.0};
  std::vector<ceres::CostFunction*> members;
  for (double c : constants) members.push_back(NewTwoRows(c));
  const BatchedCostFunction batch(members);
  EXPECT_EQ(batch.num_members(), 3);
  EXPECT_EQ(batch.num_residuals(), 6);
  EXPECT_EQ(batch.parameter_block_sizes(), std::vector<int32_t>({1, 2}));

  const double x[] = {3.0};
  const double y[] = {-0.7, 1.3};
  const double* blocks[] = {x, y};
  std::vector<double> residuals, dx, dy;
  EvaluateMembersAlone(constants, blocks, &residuals, &dx, &dy);

  std::vector<double> r(6), jx(6), jy(12);
  double* jacobians[] = {jx.data(), jy.data()};
  ASSERT_TRUE(batch.Evaluate(blocks, r.data(), jacobians));
  EXPECT_EQ(r, residuals);
  EXPECT_EQ(jx, dx);  // rows stacked, each row-major over its block
  EXPECT_EQ(jy, dy);

  // One block's Jacobian not asked for: the other still filled.
  std::vector<double> only_y(12, 0.0);
  double* partial[] = {nullptr, only_y.data()};
  ASSERT_TRUE(batch.Evaluate(blocks, r.data(), partial));
  EXPECT_EQ(only_y, dy);
  // No Jacobians: the residuals alone.
  std::vector<double> values(6, 0.0);
  ASSERT_TRUE(batch.Evaluate(blocks, values.data(), nullptr));
  EXPECT_EQ(values, residuals);
}

TEST(BatchedCostFunction, FailsWhenAnyMemberFails) {
  const BatchedCostFunction batch({NewTwoRows(0.5), NewTwoRows(2.0)});
  const double y[] = {1.0, 1.0};
  double r[4];
  const double fine[] = {3.0};
  const double* at_fine[] = {fine, y};
  EXPECT_TRUE(batch.Evaluate(at_fine, r, nullptr));
  const double between[] = {1.0};  // the second member fails (x0 < 2)
  const double* at_between[] = {between, y};
  EXPECT_FALSE(batch.Evaluate(at_between, r, nullptr));
}

}  // namespace
}  // namespace dwellfit
