#include "dwellfit/estimator/fit/bound_rest_watcher.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "ceres/autodiff_cost_function.h"
#include "ceres/problem.h"
#include "ceres/solver.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// One parameter block {y, x}: x (index 1, so that the index and the position
// in the watched list differ) is bounded below by 0.
constexpr int kY = 0;
constexpr int kX = 1;
constexpr int kSteps = 3;

// r = x + coupling * y + offset: pulls x towards -(coupling * y + offset).
struct PullOnX {
  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    residual[0] = p[kX] + coupling * p[kY] + offset;
    return true;
  }
  double offset;
  double coupling;
};

// r = exp(y) - 5: from y = 12 Gauss-Newton steps about one unit at a time
// towards log(5), so the solve takes many steps.
struct SlowY {
  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    using std::exp;
    residual[0] = exp(p[kY]) - 5.0;
    return true;
  }
};

// Records, after every successful step, whether x sits exactly on 0.
class AtBoundRecorder : public ceres::IterationCallback {
 public:
  explicit AtBoundRecorder(const double* parameters) : parameters_(parameters) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0 && summary.step_is_successful) {
      at_bound.push_back(parameters_[kX] == 0.0);
    }
    return ceres::SOLVER_CONTINUE;
  }

  // The longest run of consecutive successful steps at the bound.
  int LongestRun() const {
    int longest = 0;
    int run = 0;
    for (bool at : at_bound) {
      run = at ? run + 1 : 0;
      longest = std::max(longest, run);
    }
    return longest;
  }

  // The run of successful steps at the bound that ends the record.
  int TrailingRun() const {
    int run = 0;
    for (auto it = at_bound.rbegin(); it != at_bound.rend() && *it; ++it) ++run;
    return run;
  }

  std::vector<bool> at_bound;

 private:
  const double* parameters_;
};

struct Outcome {
  std::array<double, 2> parameters{};
  ceres::Solver::Summary summary;
  std::vector<bool> at_bound;
  int longest_run = 0;
  int trailing_run = 0;
  std::optional<int> resting;
};

// Solves from y = 12, x = 1 with x >= 0; with a watcher of `steps` steps on
// x (and on y at -50, never reached) unless `steps` is 0.
Outcome SolveFrom(const PullOnX& pull, int steps) {
  Outcome outcome;
  outcome.parameters[kY] = 12.0;
  outcome.parameters[kX] = 1.0;
  double* p = outcome.parameters.data();
  ceres::Problem problem;
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PullOnX, 1, 2>(new PullOnX(pull)),
                           nullptr, p);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SlowY, 1, 2>(new SlowY), nullptr, p);
  problem.SetParameterLowerBound(p, kX, 0.0);

  ceres::Solver::Options options;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.logging_type = ceres::SILENT;
  options.update_state_every_iteration = true;
  AtBoundRecorder recorder(p);
  options.callbacks.push_back(&recorder);  // first: it sees the step that stops the solve
  std::optional<BoundRestWatcher> watcher;
  if (steps > 0) {
    watcher.emplace(std::vector<BoundRestWatcher::Entry>{{p + kX, 0.0, kX}, {p + kY, -50.0, kY}},
                    steps);
    options.callbacks.push_back(&*watcher);
  }
  ceres::Solve(options, &problem, &outcome.summary);
  outcome.at_bound = recorder.at_bound;
  outcome.longest_run = recorder.LongestRun();
  outcome.trailing_run = recorder.TrailingRun();
  if (watcher) outcome.resting = watcher->resting();
  return outcome;
}

// The cost pulls x through its bound (r = x + 1) while y needs many steps:
// x sits on 0 and the watcher stops the solve, successfully, at the kSteps-th
// successful step in a row there, reporting x's index. Without it the solve
// would have gone on.
TEST(BoundRestWatcher, StopsWhenAParameterRestsOnItsBound) {
  const PullOnX pull{1.0, 0.0};
  const Outcome free_run = SolveFrom(pull, 0);
  ASSERT_TRUE(free_run.summary.IsSolutionUsable());
  ASSERT_EQ(free_run.parameters[kX], 0.0);
  ASSERT_GT(free_run.trailing_run, kSteps);  // the watcher has something to cut short

  const Outcome watched = SolveFrom(pull, kSteps);
  EXPECT_EQ(watched.summary.termination_type, ceres::USER_SUCCESS) << watched.summary.FullReport();
  ASSERT_TRUE(watched.resting.has_value());
  EXPECT_EQ(*watched.resting, kX);
  EXPECT_EQ(watched.parameters[kX], 0.0);
  // Stopped at the first moment x had sat there kSteps steps, not later.
  EXPECT_EQ(watched.trailing_run, kSteps);
  EXPECT_EQ(watched.longest_run, kSteps);
  EXPECT_LT(watched.at_bound.size(), free_run.at_bound.size());
  EXPECT_GT(std::abs(watched.parameters[kY] - std::log(5.0)), 1e-3);  // y not yet converged
}

// With the optimum inside the feasible side (r = x - 1) x never rests on its
// bound: the solve converges normally and nothing is reported.
TEST(BoundRestWatcher, SilentWhenTheOptimumIsInside) {
  const Outcome watched = SolveFrom(PullOnX{-1.0, 0.0}, kSteps);
  EXPECT_EQ(watched.summary.termination_type, ceres::CONVERGENCE) << watched.summary.FullReport();
  EXPECT_FALSE(watched.resting.has_value());
  EXPECT_GT(static_cast<int>(watched.at_bound.size()), kSteps);  // it had the chance
  EXPECT_NEAR(watched.parameters[kX], 1.0, 1e-6);
  EXPECT_NEAR(watched.parameters[kY], std::log(5.0), 1e-6);
}

// x is pulled onto its bound while y is large (r = x + y - 10.5) and leaves it
// as y falls below 10.5: fewer than kSteps steps on the bound are not
// reported, though a watcher asking for just that many would have stopped.
TEST(BoundRestWatcher, IgnoresAShortRestOnTheBound) {
  const PullOnX pull{-10.5, 1.0};
  const Outcome watched = SolveFrom(pull, kSteps);
  // The premise: x touched the bound, fewer than kSteps steps in a row, and
  // the solve went on for more than kSteps steps after all.
  ASSERT_GE(watched.longest_run, 1);
  ASSERT_LT(watched.longest_run, kSteps);
  ASSERT_GT(static_cast<int>(watched.at_bound.size()), kSteps);

  EXPECT_EQ(watched.summary.termination_type, ceres::CONVERGENCE) << watched.summary.FullReport();
  EXPECT_FALSE(watched.resting.has_value());
  EXPECT_NEAR(watched.parameters[kX], 10.5 - std::log(5.0), 1e-6);

  const Outcome shorter = SolveFrom(pull, watched.longest_run);
  EXPECT_EQ(shorter.summary.termination_type, ceres::USER_SUCCESS);
  ASSERT_TRUE(shorter.resting.has_value());
  EXPECT_EQ(*shorter.resting, kX);
}

// A successful step's summary, as the solver hands it to its callbacks.
ceres::IterationSummary SuccessfulStep(int iteration) {
  ceres::IterationSummary summary;
  summary.iteration = iteration;
  summary.step_is_successful = true;
  return summary;
}

// With non-monotonic steps the caller's block keeps the best point while the
// iterate moves: an entry resting on its bound in the iterate alone stops the
// solve after kSteps steps, and says so; resting in both, it does not.
TEST(BoundRestWatcher, ReadsTheIterateBesideTheBestPoint) {
  double best = 2.5;
  double iterate = 0.0;
  BoundRestWatcher watcher({{&best, 0.0, kX, &iterate}}, kSteps);
  for (int i = 1; i < kSteps; ++i) {
    EXPECT_EQ(watcher(SuccessfulStep(i)), ceres::SOLVER_CONTINUE) << i;
  }
  ceres::IterationSummary rejected = SuccessfulStep(kSteps);
  rejected.step_is_successful = false;
  EXPECT_EQ(watcher(rejected), ceres::SOLVER_CONTINUE);  // not a step at the bound
  EXPECT_EQ(watcher(SuccessfulStep(kSteps + 1)), ceres::SOLVER_TERMINATE_SUCCESSFULLY);
  ASSERT_TRUE(watcher.resting().has_value());
  EXPECT_EQ(*watcher.resting(), kX);
  EXPECT_TRUE(watcher.resting_at_iterate());

  // Both on the bound: the best point rests there, nothing to move to.
  best = 0.0;
  BoundRestWatcher both({{&best, 0.0, kX, &iterate}}, kSteps);
  for (int i = 1; i < kSteps; ++i) EXPECT_EQ(both(SuccessfulStep(i)), ceres::SOLVER_CONTINUE);
  EXPECT_EQ(both(SuccessfulStep(kSteps)), ceres::SOLVER_TERMINATE_SUCCESSFULLY);
  EXPECT_FALSE(both.resting_at_iterate());

  // The iterate leaves the bound: the count starts again.
  best = 2.5;
  BoundRestWatcher left({{&best, 0.0, kX, &iterate}}, kSteps);
  for (int i = 1; i < kSteps; ++i) EXPECT_EQ(left(SuccessfulStep(i)), ceres::SOLVER_CONTINUE);
  iterate = 0.5;
  EXPECT_EQ(left(SuccessfulStep(kSteps)), ceres::SOLVER_CONTINUE);
  iterate = 0.0;
  EXPECT_EQ(left(SuccessfulStep(kSteps + 1)), ceres::SOLVER_CONTINUE);
  EXPECT_FALSE(left.resting().has_value());
}

}  // namespace
}  // namespace dwellfit
