#include "dwellfit/estimator/fit/batched_cost_function.h"

#include <memory>
#include <vector>

#include "ceres/autodiff_cost_function.h"
#include "dwellfit/residuals/functors/algebraic_residual.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "dwellfit/residuals/model/response_model.h"
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

// Dwells around the thesis model's fold at 40-42 Hz (w = 2 pi 40 rad/s), on
// both branches and past their ends, with weights and a floor that differ.
struct DwellArgs {
  double omega_rad_s, a_base, a, weight;
  Branch branch;
};
std::vector<DwellArgs> FoldDwells() {
  std::vector<DwellArgs> dwells;
  const Branch branches[] = {Branch::kLower, Branch::kUpper, Branch::kOnly};
  for (int i = 0; i < 9; ++i) {
    dwells.push_back(
        {kTwoPi * (39.5 + 0.3 * i), 0.01, 0.0004 * (1 + i % 4), 1.0 + 0.1 * i, branches[i % 3]});
  }
  return dwells;
}

// The batch's residuals and Jacobian rows at `p` are, bit for bit, those of
// each member's own cost function in `alone`, with Jacobians and without (in
// double then, as a cost function evaluates without them: a Jet divided by
// a double is multiplied by its reciprocal, so the value may differ from the
// Jet's in the last bit). Each member is evaluated with Jacobians first, as
// its cost function is, so warm-started roots start from the same place.
void ExpectBatchGivesEachAlone(const ceres::CostFunction& batch,
                               const std::vector<std::unique_ptr<ceres::CostFunction>>& alone,
                               const ParameterVector& p) {
  const double* blocks[] = {p.data()};
  std::vector<double> r(alone.size()), j(alone.size() * kNumParameters);
  double* jacobians[] = {j.data()};
  ASSERT_TRUE(batch.Evaluate(blocks, r.data(), jacobians));
  std::vector<double> value_only(alone.size());
  ASSERT_TRUE(batch.Evaluate(blocks, value_only.data(), nullptr));
  for (size_t i = 0; i < alone.size(); ++i) {
    double r_alone, j_alone[kNumParameters];
    double* jacobians_alone[] = {j_alone};
    ASSERT_TRUE(alone[i]->Evaluate(blocks, &r_alone, jacobians_alone));
    EXPECT_EQ(r[i], r_alone) << "dwell " << i;
    for (int k = 0; k < kNumParameters; ++k) {
      EXPECT_EQ(j[i * kNumParameters + k], j_alone[k]) << "dwell " << i << " entry " << k;
    }
    double r_value_only;
    ASSERT_TRUE(alone[i]->Evaluate(blocks, &r_value_only, nullptr));
    EXPECT_EQ(value_only[i], r_value_only) << "dwell " << i;
  }
}

// A FunctorBatch of vertical errors gives, bit for bit, the residuals and
// Jacobian rows of one AutoDiffCostFunction per dwell, at two points (the
// second evaluation warm-starts each dwell's root), and its members' addresses
// stay those Add returned.
TEST(FunctorBatch, GivesEachDwellsAutodiffCostFunctionsValuesBitForBit) {
  const std::vector<DwellArgs> dwells = FoldDwells();
  FunctorBatch<VerticalErrorResidual> batch(kFirstOrderForm);
  std::vector<std::unique_ptr<ceres::CostFunction>> alone;
  std::vector<const VerticalErrorResidual*> added;
  for (const DwellArgs& d : dwells) {
    added.push_back(batch.Add(kFirstOrderForm, d.omega_rad_s, d.a_base, d.a, d.branch,
                              ErrorMeasure::kRelative, d.weight, 1e-6));
    alone.emplace_back(VerticalErrorResidual::Create(kFirstOrderForm, d.omega_rad_s, d.a_base, d.a,
                                                     d.branch, ErrorMeasure::kRelative, d.weight,
                                                     1e-6));
  }
  ASSERT_EQ(batch.num_residuals(), static_cast<int>(dwells.size()));
  ASSERT_EQ(batch.parameter_block_sizes(), std::vector<int32_t>{kNumParameters});
  for (size_t i = 1; i < added.size(); ++i) EXPECT_NE(added[i], added[i - 1]);
  const ParameterVector points[] = {{100.0, 0.2, 300.0, 1.0e4, 9.0e8, kTwoPi * 40.0},
                                    {104.0, 0.19, 310.0, 1.1e4, 9.3e8, kTwoPi * 40.1}};
  for (const ParameterVector& p : points) ExpectBatchGivesEachAlone(batch, alone, p);
}

// The same for the algebraic residuals of eq. (3.11).
TEST(FunctorBatch, GivesEachAlgebraicResidualsAutodiffValuesBitForBit) {
  const std::vector<DwellArgs> dwells = FoldDwells();
  FunctorBatch<AlgebraicResidual> batch(kFirstOrderForm);
  std::vector<std::unique_ptr<ceres::CostFunction>> alone;
  for (const DwellArgs& d : dwells) {
    batch.Add(kFirstOrderForm, d.omega_rad_s, d.a_base, d.a, d.weight);
    alone.emplace_back(
        AlgebraicResidual::Create(kFirstOrderForm, d.omega_rad_s, d.a_base, d.a, d.weight));
  }
  ExpectBatchGivesEachAlone(batch, alone, {104.0, 0.19, 310.0, 1.1e4, 9.3e8, kTwoPi * 40.1});
}

TEST(FunctorBatch, FailsWhenAnyMemberFails) {
  const ParameterVector p = {100.0, 0.2, 300.0, 1.0e4, 9.0e8, kTwoPi * 40.0};
  const double* blocks[] = {p.data()};
  double r[2];
  FunctorBatch<VerticalErrorResidual> batch(kFirstOrderForm);
  batch.Add(kFirstOrderForm, kTwoPi * 40.0, 0.01, 0.001, Branch::kOnly, ErrorMeasure::kRelative,
            1.0, 0.0);
  EXPECT_TRUE(batch.Evaluate(blocks, r, nullptr));
  // A drive level of 0 has no root to solve for: this member fails.
  batch.Add(kFirstOrderForm, kTwoPi * 41.0, 0.0, 0.001, Branch::kOnly, ErrorMeasure::kRelative, 1.0,
            0.0);
  EXPECT_FALSE(batch.Evaluate(blocks, r, nullptr));
}

}  // namespace
}  // namespace dwellfit
