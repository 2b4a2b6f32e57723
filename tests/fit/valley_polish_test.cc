// The valley polish (estimator/fit/valley_polish.h): the creep watcher's
// rule, the polish on a problem whose Gauss-Newton iteration converges only
// linearly, its bounds and its refusal of a rank-deficient Jacobian, and the
// staged solve with and without it on a sweep of 20,000 simulated dwells.
#include "dwellfit/estimator/fit/valley_polish.h"

#include <cmath>
#include <memory>
#include <vector>

#include "ceres/autodiff_cost_function.h"
#include "ceres/problem.h"
#include "ceres/solver.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

ceres::IterationSummary Step(int iteration, bool successful, double ratio) {
  ceres::IterationSummary summary;
  summary.iteration = iteration;
  summary.step_is_successful = successful;
  summary.relative_decrease = ratio;
  return summary;
}

TEST(CreepWatcher, StopsAfterTheGivenStepsInARowAboveTheRatio) {
  CreepWatcher watcher(3, 1.5);
  EXPECT_EQ(watcher(Step(0, true, 2.0)), ceres::SOLVER_CONTINUE);  // the start: no step
  EXPECT_EQ(watcher(Step(1, true, 1.9)), ceres::SOLVER_CONTINUE);
  EXPECT_EQ(watcher(Step(2, true, 1.6)), ceres::SOLVER_CONTINUE);
  EXPECT_FALSE(watcher.creeping());
  EXPECT_EQ(watcher(Step(3, true, 2.4)), ceres::SOLVER_TERMINATE_SUCCESSFULLY);
  EXPECT_TRUE(watcher.creeping());
}

TEST(CreepWatcher, AnOrdinaryOrFailedStepStartsTheCountAgain) {
  CreepWatcher watcher(3, 1.5);
  const ceres::IterationSummary steps[] = {
      Step(1, true, 1.9), Step(2, true, 1.9), Step(3, true, 1.2),   // a step as predicted
      Step(4, true, 1.9), Step(5, true, 1.9), Step(6, false, 3.0),  // a rejected step
      Step(7, true, 1.9), Step(8, true, 1.9), Step(9, true, 1.5)};  // not above 1.5
  for (const ceres::IterationSummary& step : steps) {
    EXPECT_EQ(watcher(step), ceres::SOLVER_CONTINUE) << "iteration " << step.iteration;
  }
  EXPECT_FALSE(watcher.creeping());
}

// r = (x + 1, lambda x^2 + x - 1, 1000 (y - 2) + x): the minimum is at x = 0,
// y = 2, where the residuals are (1, -1, 0). The Gauss-Newton model's
// curvature along x is 2, the true one 2 - 2 lambda: Gauss-Newton converges
// linearly at the rate lambda and each step lowers the cost 1 + lambda times
// as much as the model predicts. The third residual couples x and y at
// scales three decades apart, so the whitening is not diagonal.
struct LargeResidual {
  explicit LargeResidual(double lambda) : lambda(lambda) {}
  template <typename T>
  bool operator()(const T* const p, T* r) const {
    r[0] = p[0] + 1.0;
    r[1] = lambda * p[0] * p[0] + p[0] - 1.0;
    r[2] = 1000.0 * (p[1] - 2.0) + p[0];
    return true;
  }
  double lambda;
};

class LargeResidualProblem : public ::testing::Test {
 protected:
  void SetUp() override {
    problem_.AddResidualBlock(
        new ceres::AutoDiffCostFunction<LargeResidual, 3, 2>(new LargeResidual(0.9)), nullptr, p_);
  }

  ceres::Solver::Options Options() const {
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.function_tolerance = 1e-14;
    options.gradient_tolerance = 1e-30;
    options.parameter_tolerance = 1e-20;
    options.max_num_iterations = 500;
    return options;
  }

  double p_[2] = {1.0, 0.0};
  ceres::Problem problem_;
};

TEST_F(LargeResidualProblem, LevenbergMarquardtCreepsThePolishConverges) {
  // Levenberg-Marquardt alone: about log(1e-6) / log(0.9) = 131 steps to
  // |x| < 1e-6.
  double alone[2] = {p_[0], p_[1]};
  {
    ceres::Problem problem;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<LargeResidual, 3, 2>(new LargeResidual(0.9)), nullptr,
        alone);
    ceres::Solver::Summary summary;
    ceres::Solve(Options(), &problem, &summary);
    EXPECT_GT(summary.iterations.size(), 60u) << summary.BriefReport();
  }
  // With the watcher the solve stops early; the polish then reaches the
  // minimum in a few BFGS iterations.
  CreepWatcher watcher(kCreepSteps, kCreepRatio);
  ceres::Solver::Options options = Options();
  options.callbacks.push_back(&watcher);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem_, &summary);
  ASSERT_TRUE(watcher.creeping());
  EXPECT_LT(summary.iterations.size(), 20u) << summary.BriefReport();
  EXPECT_GT(std::abs(p_[0]), 1e-3) << "stopped while still far";
  SolverSettings settings;
  settings.function_tolerance = 1e-14;
  const ValleyPolish polish = PolishAlongValley(&problem_, {p_}, settings);
  EXPECT_TRUE(polish.improved) << polish.message;
  EXPECT_LT(polish.iterations, 15) << polish.message;
  EXPECT_LT(polish.final_cost, polish.initial_cost);
  EXPECT_NEAR(p_[0], 0.0, 1e-6) << polish.message;
  EXPECT_NEAR(p_[1], 2.0, 1e-9) << polish.message;
  EXPECT_NEAR(polish.final_cost, 1.0, 1e-12);  // (1/2)(1 + 1)
}

TEST_F(LargeResidualProblem, ThePolishKeepsToTheLowerBounds) {
  problem_.SetParameterLowerBound(p_, 0, 0.5);
  p_[0] = 0.8;
  p_[1] = 1.9;
  SolverSettings settings;
  settings.function_tolerance = 1e-14;
  const ValleyPolish polish = PolishAlongValley(&problem_, {p_}, settings);
  EXPECT_TRUE(polish.improved) << polish.message;
  EXPECT_GE(p_[0], 0.5);
  // The cost falls towards x = 0: x moves most of the way to its bound (the
  // trust-region solve that resumes after a polish holds it there).
  EXPECT_LT(p_[0], 0.55);
}

// r = (x + y - 1, 2 (x + y) - 3): only x + y is determined.
struct SumOnly {
  template <typename T>
  bool operator()(const T* const p, T* r) const {
    r[0] = p[0] + p[1] - 1.0;
    r[1] = 2.0 * (p[0] + p[1]) - 3.0;
    return true;
  }
};

TEST(ValleyPolish, ARankDeficientJacobianLeavesTheBlocksUntouched) {
  double p[2] = {0.25, 0.5};
  ceres::Problem problem;
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SumOnly, 2, 2>(new SumOnly), nullptr, p);
  const ValleyPolish polish = PolishAlongValley(&problem, {p}, SolverSettings{});
  EXPECT_FALSE(polish.improved);
  EXPECT_EQ(polish.iterations, 0);
  EXPECT_THAT(polish.message, HasSubstr("rank-deficient"));
  EXPECT_EQ(p[0], 0.25);
  EXPECT_EQ(p[1], 0.5);
}

// The thesis case's frequency sweep, 10,000 dwells each way at 1 % noise,
// fitted from the thesis start (30 % off) with omega known.
class LargeSweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SweepPlan frequency;
    frequency.id = "F";
    frequency.kind = SweepKind::kFrequency;
    frequency.held_a_base = 0.01;
    frequency.from = 38.0;
    frequency.to = 45.9992;
    frequency.step = 8e-4;
    DwellPlan plan;
    plan.truth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};
    plan.sweeps = {frequency};
    plan.noise = {0.01, 1};
    sweeps_ = new std::vector<Sweep>(SimulateDwells(plan));
    DetectJumps(JumpDetectionOptions{}, sweeps_);
  }
  static void TearDownTestSuite() { delete sweeps_; }

  static IdentificationResult Fit(bool valley_polish) {
    IdentificationOptions options;
    options.initial = {130.0, 0.14, 390.0, 7000.0, 1.17e9, HzToRadPerSecond(40.0)};
    options.fixed[kNaturalFrequency] = true;
    options.solve.residual.error = ErrorMeasure::kRelative;
    options.solve.solver.valley_polish = valley_polish;
    return Identify({&(*sweeps_)[0], &(*sweeps_)[1]}, options);
  }

  static std::vector<Sweep>* sweeps_;
};
std::vector<Sweep>* LargeSweep::sweeps_ = nullptr;

TEST_F(LargeSweep, ThePolishReachesALowerCostInFewerIterations) {
  ASSERT_EQ(sweeps_->size(), 2u);
  ASSERT_EQ((*sweeps_)[0].points.size(), 10000u);
  const IdentificationResult polished = Fit(true);
  const IdentificationResult alone = Fit(false);
  ASSERT_EQ(polished.status, FitStatus::kConverged) << polished.message;
  ASSERT_EQ(alone.status, FitStatus::kConverged) << alone.message;
  ASSERT_EQ(polished.stages.size(), 2u);
  EXPECT_THAT(polished.stages[1].note, HasSubstr("valley polish"));
  EXPECT_THAT(alone.stages[1].note, ::testing::Not(HasSubstr("valley polish")));
  // Levenberg-Marquardt alone creeps and stops on the function tolerance
  // short of the minimum; polished, the fit ends lower in fewer steps.
  EXPECT_LT(polished.final_cost, alone.final_cost);
  EXPECT_LT(polished.iterations, alone.iterations)
      << polished.iterations << " against " << alone.iterations;
  // Both near the truth; the polished delta nearer.
  const double truth_delta = 1e4;
  EXPECT_LT(std::abs(polished.parameters[kDelta] - truth_delta),
            std::abs(alone.parameters[kDelta] - truth_delta));
  EXPECT_NEAR(polished.parameters[kEtaE], 100.0, 0.1);
}

}  // namespace
}  // namespace dwellfit
