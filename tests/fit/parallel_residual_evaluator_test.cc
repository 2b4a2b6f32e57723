#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"

#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "ceres/autodiff_cost_function.h"
#include "ceres/problem.h"
#include "ceres/sized_cost_function.h"
#include "ceres/solver.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using Parameters = std::array<double, 3>;

const Parameters kTruth = {2.0, 0.3, 1.5};  // y = a exp(-b t) cos(c t)
const Parameters kStart = {0.5, 1.0, 1.3};  // far enough for rejected steps
constexpr int kNumSamples = 2400;           // enough blocks for three threads

struct Sample {
  double t = 0.0;
  double y = 0.0;
};

// y = a exp(-b t) cos(c t) at kTruth plus a fixed pseudo-noise.
std::vector<Sample> SyntheticData(int n) {
  std::vector<Sample> data(n);
  for (int i = 0; i < n; ++i) {
    data[i].t = 10.0 * i / n;
    data[i].y = kTruth[0] * std::exp(-kTruth[1] * data[i].t) * std::cos(kTruth[2] * data[i].t) +
                0.01 * std::sin(12.9898 * i + 0.5);
  }
  return data;
}

struct DecayingCosine {
  explicit DecayingCosine(const Sample& sample) : t(sample.t), y(sample.y) {}
  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    using std::cos;
    using std::exp;
    residual[0] = p[0] * exp(-p[1] * t) * cos(p[2] * t) - y;
    return true;
  }
  double t;
  double y;
};

ceres::CostFunction* NewDecayingCosine(const Sample& sample) {
  return new ceres::AutoDiffCostFunction<DecayingCosine, 1, 3>(new DecayingCosine(sample));
}

ceres::Solver::Options FitOptions() {
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  options.num_threads = 1;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-12;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.logging_type = ceres::SILENT;
  return options;
}

struct Fit {
  Parameters parameters{};
  ceres::Solver::Summary summary;
  std::int64_t replayed = 0;
  std::int64_t evaluated_directly = 0;
};

// Fits the data from kStart with every block wrapped by an evaluator on
// `num_threads` threads.
Fit FitWithEvaluator(const std::vector<Sample>& data, int num_threads) {
  Fit fit;
  fit.parameters = kStart;
  ParallelResidualEvaluator evaluator({{fit.parameters.data(), 3}}, num_threads);
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &evaluator;
  ceres::Problem problem(problem_options);
  for (const Sample& sample : data) {
    problem.AddResidualBlock(evaluator.Wrap(NewDecayingCosine(sample), {fit.parameters.data()}),
                             nullptr, fit.parameters.data());
  }
  ceres::Solve(FitOptions(), &problem, &fit.summary);
  fit.replayed = evaluator.replayed();
  fit.evaluated_directly = evaluator.evaluated_directly();
  return fit;
}

// The same fit with Ceres calling the cost functions itself.
Fit FitWithoutEvaluator(const std::vector<Sample>& data) {
  Fit fit;
  fit.parameters = kStart;
  ceres::Problem problem;
  for (const Sample& sample : data) {
    problem.AddResidualBlock(NewDecayingCosine(sample), nullptr, fit.parameters.data());
  }
  ceres::Solve(FitOptions(), &problem, &fit.summary);
  return fit;
}

// Records the threads it is evaluated on, and otherwise is DecayingCosine.
// Until `wait_for` distinct threads have evaluated some block (or its
// deadline, 10 s after the record was made, has passed), each evaluation
// waits for another thread to arrive: a pool that really runs blocks on
// several threads gets them, whatever the machine's load, and one that does
// not is found out.
class ThreadRecordingCost : public ceres::SizedCostFunction<1, 3> {
 public:
  struct Record {
    std::mutex mutex;
    std::condition_variable arrived;
    std::set<std::thread::id> threads;
    size_t wait_for = 1;
    std::chrono::steady_clock::time_point deadline =
        std::chrono::steady_clock::now() + std::chrono::seconds(10);
  };

  ThreadRecordingCost(const Sample& sample, Record* record)
      : cost_(NewDecayingCosine(sample)), record_(record) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    {
      std::unique_lock<std::mutex> lock(record_->mutex);
      if (record_->threads.insert(std::this_thread::get_id()).second) {
        record_->arrived.notify_all();
      }
      record_->arrived.wait_until(lock, record_->deadline,
                                  [this] { return record_->threads.size() >= record_->wait_for; });
    }
    return cost_->Evaluate(parameters, residuals, jacobians);
  }

 private:
  const std::unique_ptr<ceres::CostFunction> cost_;
  Record* const record_;
};

// The distinct threads that evaluate `blocks` wrapped blocks in one
// CostGradient with `num_threads` threads, the blocks waiting for
// `wait_for` of them.
int ThreadsUsed(int blocks, int num_threads, size_t wait_for,
                int min_rows_per_thread = ParallelResidualEvaluator::kMinRowsPerThread) {
  const std::vector<Sample> data = SyntheticData(blocks);
  ThreadRecordingCost::Record record;
  record.wait_for = wait_for;
  Parameters parameters = kStart;
  ParallelResidualEvaluator evaluator({{parameters.data(), 3}}, num_threads, min_rows_per_thread);
  std::vector<std::unique_ptr<ceres::CostFunction>> wrappers;
  for (const Sample& sample : data) {
    wrappers.emplace_back(
        evaluator.Wrap(new ThreadRecordingCost(sample, &record), {parameters.data()}));
  }
  std::vector<double> gradient;
  EXPECT_TRUE(evaluator.CostGradient(parameters.data(), &gradient));
  return static_cast<int>(record.threads.size());
}

// r = sqrt(x - shift), which fails to evaluate for x < shift.
class SqrtCost : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit SqrtCost(double shift) : shift_(shift) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double d = parameters[0][0] - shift_;
    if (d < 0.0) return false;
    residuals[0] = std::sqrt(d);
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = 0.5 / std::sqrt(d);
    return true;
  }

 private:
  const double shift_;
};

// The threads the other tests rely on are really used: one thread (the
// caller's) when asked for one or below kMinRowsPerThread residuals per
// thread, two when
// asked for two with enough residuals, or with fewer where the evaluator is
// told a lower threshold.
TEST(ParallelResidualEvaluator, PrecomputesOnTheRequestedThreads) {
  EXPECT_EQ(ThreadsUsed(kNumSamples, 1, 1), 1);
  EXPECT_EQ(ThreadsUsed(300, 3, 1), 1);
  EXPECT_EQ(ThreadsUsed(2 * ParallelResidualEvaluator::kMinRowsPerThread - 1, 2, 1), 1);
  EXPECT_EQ(ThreadsUsed(kNumSamples, 2, 2), 2);
  EXPECT_EQ(ThreadsUsed(300, 2, 2, 100), 2);
}

// The solve does not depend on the number of threads: the final parameters
// and cost are bitwise the same on 1, 2 and 3 threads, and agree with a solve
// in which Ceres evaluates the cost functions itself.
TEST(ParallelResidualEvaluator, SolveIsBitwiseIndependentOfThreadCount) {
  const std::vector<Sample> data = SyntheticData(kNumSamples);
  const Fit one = FitWithEvaluator(data, 1);
  ASSERT_EQ(one.summary.termination_type, ceres::CONVERGENCE) << one.summary.FullReport();
  ASSERT_GT(one.summary.num_successful_steps, 2);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(one.parameters[i], kTruth[i], 1e-2) << i;

  for (int threads : {2, 3}) {
    const Fit many = FitWithEvaluator(data, threads);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(many.parameters[i], one.parameters[i]) << threads;
    EXPECT_EQ(many.summary.final_cost, one.summary.final_cost) << threads;
    EXPECT_EQ(many.summary.iterations.size(), one.summary.iterations.size()) << threads;
  }

  const Fit plain = FitWithoutEvaluator(data);
  ASSERT_EQ(plain.summary.termination_type, ceres::CONVERGENCE);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(one.parameters[i], plain.parameters[i], 1e-9 * std::abs(plain.parameters[i])) << i;
  }
  EXPECT_NEAR(one.summary.final_cost, plain.summary.final_cost, 1e-9 * plain.summary.final_cost);
}

// During a solve every wrapper call Ceres makes is answered from the values
// the callback precomputed: one call per block per Ceres evaluation (residual
// or Jacobian), none of them evaluated directly, rejected steps included.
TEST(ParallelResidualEvaluator, SolveReplaysEveryEvaluation) {
  const std::vector<Sample> data = SyntheticData(kNumSamples);
  for (int threads : {1, 3}) {
    const Fit fit = FitWithEvaluator(data, threads);
    ASSERT_EQ(fit.summary.termination_type, ceres::CONVERGENCE);
    // Rejected steps too: Ceres goes back to a point it evaluated before.
    ASSERT_GT(fit.summary.num_unsuccessful_steps, 0);
    EXPECT_GT(fit.replayed, 0) << threads;
    EXPECT_EQ(fit.evaluated_directly, 0) << threads;
    const std::int64_t evaluations =
        fit.summary.num_residual_evaluations + fit.summary.num_jacobian_evaluations;
    EXPECT_EQ(fit.replayed + fit.evaluated_directly, evaluations * kNumSamples) << threads;
  }
}

// (1/2) sum r^2 of the decaying cosine over `data` at `p`.
double CosineCost(const std::vector<Sample>& data, const double* p) {
  double cost = 0.0;
  for (const Sample& sample : data) {
    double r = 0.0;
    const DecayingCosine cosine(sample);
    cosine(p, &r);
    cost += 0.5 * r * r;
  }
  return cost;
}

// After every accepted step, the cost at the evaluator's iterate and at the
// caller's block, beside the cost Ceres reports for its iterate.
class IterateRecorder : public ceres::IterationCallback {
 public:
  IterateRecorder(const std::vector<Sample>* data, const ParallelResidualEvaluator* evaluator,
                  const double* parameters)
      : data_(data), evaluator_(evaluator), parameters_(parameters) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (!summary.step_is_successful) return ceres::SOLVER_CONTINUE;
    steps.push_back({summary.cost, CosineCost(*data_, evaluator_->IterateEntry(parameters_)),
                     CosineCost(*data_, parameters_), summary.step_is_nonmonotonic});
    return ceres::SOLVER_CONTINUE;
  }

  struct Step {
    double solver_cost, iterate_cost, block_cost;
    bool nonmonotonic;
  };
  std::vector<Step> steps;

 private:
  const std::vector<Sample>* data_;
  const ParallelResidualEvaluator* evaluator_;
  const double* parameters_;
};

// The evaluator's iterate is the solver's: with non-monotonic steps its cost
// is the cost Ceres reports at every accepted step, also where the cost rose
// and Ceres keeps the best point so far in the caller's block instead.
TEST(ParallelResidualEvaluator, IterateIsTheSolversIterate) {
  const std::vector<Sample> data = SyntheticData(kNumSamples);
  Parameters parameters = {4.0, -0.1, 1.0};  // growing, not decaying: the cost rises on the way
  ParallelResidualEvaluator evaluator({{parameters.data(), 3}}, 2);
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &evaluator;
  ceres::Problem problem(problem_options);
  for (const Sample& sample : data) {
    problem.AddResidualBlock(evaluator.Wrap(NewDecayingCosine(sample), {parameters.data()}),
                             nullptr, parameters.data());
  }
  ceres::Solver::Options options = FitOptions();
  options.use_nonmonotonic_steps = true;
  options.update_state_every_iteration = true;
  IterateRecorder recorder(&data, &evaluator, parameters.data());
  options.callbacks.push_back(&recorder);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();

  int nonmonotonic = 0;
  for (const IterateRecorder::Step& step : recorder.steps) {
    EXPECT_NEAR(step.iterate_cost, step.solver_cost, 1e-12 * step.solver_cost);
    if (!step.nonmonotonic) continue;
    ++nonmonotonic;
    EXPECT_LT(step.block_cost, step.iterate_cost);  // the best point, not the iterate
  }
  EXPECT_GT(nonmonotonic, 0) << "the premise: some accepted step raised the cost";
  double outside = 0.0;
  EXPECT_EQ(evaluator.IterateEntry(&outside), nullptr);
}

// The decaying cosine on two blocks: {a} and {b, c}.
struct SplitDecayingCosine {
  explicit SplitDecayingCosine(const Sample& sample) : cosine(sample) {}
  template <typename T>
  bool operator()(const T* const a, const T* const bc, T* residual) const {
    const T p[3] = {a[0], bc[0], bc[1]};
    return cosine(p, residual);
  }
  DecayingCosine cosine;
};

// The same fit with the parameters in two blocks, every residual block
// reading both through one evaluator: every evaluation replayed, the point
// the one-block fit reaches, bitwise the same on 1 and 3 threads, and the
// gradient in the blocks' concatenated coordinates.
TEST(ParallelResidualEvaluator, SeveralBlocksReplayEveryEvaluation) {
  const std::vector<Sample> data = SyntheticData(kNumSamples);
  const Fit one_block = FitWithEvaluator(data, 1);
  std::vector<double> first;
  for (int threads : {1, 3}) {
    double a[1] = {kStart[0]};
    double bc[2] = {kStart[1], kStart[2]};
    ParallelResidualEvaluator evaluator({{a, 1}, {bc, 2}}, threads);
    ceres::Problem::Options problem_options;
    problem_options.evaluation_callback = &evaluator;
    ceres::Problem problem(problem_options);
    for (const Sample& sample : data) {
      auto* cost = new ceres::AutoDiffCostFunction<SplitDecayingCosine, 1, 1, 2>(
          new SplitDecayingCosine(sample));
      problem.AddResidualBlock(evaluator.Wrap(cost, {a, bc}), nullptr, a, bc);
    }
    ceres::Solver::Summary summary;
    ceres::Solve(FitOptions(), &problem, &summary);
    ASSERT_EQ(summary.termination_type, ceres::CONVERGENCE);
    EXPECT_EQ(evaluator.evaluated_directly(), 0) << threads;
    EXPECT_EQ(evaluator.replayed(),
              (summary.num_residual_evaluations + summary.num_jacobian_evaluations) * kNumSamples)
        << threads;
    const std::vector<double> estimate = {a[0], bc[0], bc[1]};
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(estimate[i], one_block.parameters[i], 1e-9 * std::abs(estimate[i])) << i;
    }
    if (first.empty()) first = estimate;
    EXPECT_EQ(estimate, first) << threads;

    const double point[3] = {1.7, 0.45, 1.4};
    double at_a[1] = {point[0]};
    double at_bc[2] = {point[1], point[2]};
    ceres::Problem plain;
    for (const Sample& sample : data) {
      plain.AddResidualBlock(new ceres::AutoDiffCostFunction<SplitDecayingCosine, 1, 1, 2>(
                                 new SplitDecayingCosine(sample)),
                             nullptr, at_a, at_bc);
    }
    double cost = 0.0;
    std::vector<double> expected;
    ASSERT_TRUE(
        plain.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &expected, nullptr));
    std::vector<double> gradient;
    ASSERT_TRUE(evaluator.CostGradient(point, &gradient));
    ASSERT_EQ(gradient.size(), 3u);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(gradient[i], expected[i], 1e-12 * std::abs(expected[i]));
  }
}

// CostGradient is J^T r at the point it is given (not the block's current
// values), as Ceres computes it for a problem without the evaluator.
TEST(ParallelResidualEvaluator, CostGradientMatchesCeresGradient) {
  const std::vector<Sample> data = SyntheticData(kNumSamples);
  const Parameters point = {1.7, 0.45, 1.4};

  Parameters at_point = point;
  ceres::Problem plain;
  for (const Sample& sample : data) {
    plain.AddResidualBlock(NewDecayingCosine(sample), nullptr, at_point.data());
  }
  double cost = 0.0;
  std::vector<double> expected;
  ASSERT_TRUE(
      plain.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &expected, nullptr));
  ASSERT_EQ(expected.size(), 3u);
  const double scale = std::hypot(expected[0], expected[1], expected[2]);
  ASSERT_GT(scale, 1.0);  // far enough from the minimum to mean something

  for (int threads : {1, 3}) {
    Parameters block = kStart;  // deliberately not `point`
    ParallelResidualEvaluator evaluator({{block.data(), 3}}, threads);
    std::vector<std::unique_ptr<ceres::CostFunction>> wrappers;
    for (const Sample& sample : data)
      wrappers.emplace_back(evaluator.Wrap(NewDecayingCosine(sample), {block.data()}));
    std::vector<double> gradient;
    ASSERT_TRUE(evaluator.CostGradient(point.data(), &gradient));
    ASSERT_EQ(gradient.size(), 3u);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(gradient[i], expected[i], 1e-12 * std::abs(expected[i])) << threads << " " << i;
    }
    EXPECT_EQ(block, kStart);  // the block itself is left alone
  }
}

// A wrapper asked about a point the callback has not seen evaluates the
// wrapped function there (counted as direct); at the point it has seen it
// replays the same values (counted as replayed).
TEST(ParallelResidualEvaluator, UnseenPointIsEvaluatedDirectly) {
  const Sample sample = SyntheticData(kNumSamples)[777];
  const std::unique_ptr<ceres::CostFunction> reference(NewDecayingCosine(sample));
  auto evaluate = [](const ceres::CostFunction& cost, const Parameters& p, double* residual,
                     Parameters* jacobian) {
    const double* blocks[] = {p.data()};
    double* jacobians[] = {jacobian->data()};
    return cost.Evaluate(blocks, residual, jacobians);
  };

  Parameters block = kStart;
  ParallelResidualEvaluator evaluator({{block.data(), 3}}, 1);
  const std::unique_ptr<ceres::CostFunction> wrapper(
      evaluator.Wrap(NewDecayingCosine(sample), {block.data()}));
  EXPECT_EQ(wrapper->num_residuals(), 1);
  EXPECT_EQ(wrapper->parameter_block_sizes(), std::vector<int32_t>{3});

  const Parameters unseen = {1.9, 0.25, 1.55};
  double expected_residual = 0.0;
  Parameters expected_jacobian{};
  ASSERT_TRUE(evaluate(*reference, unseen, &expected_residual, &expected_jacobian));

  // Before the callback has run at all.
  double residual = 0.0;
  Parameters jacobian{};
  ASSERT_TRUE(evaluate(*wrapper, unseen, &residual, &jacobian));
  EXPECT_EQ(residual, expected_residual);
  EXPECT_EQ(jacobian, expected_jacobian);
  EXPECT_EQ(evaluator.evaluated_directly(), 1);
  EXPECT_EQ(evaluator.replayed(), 0);

  // After it has precomputed the values at kStart.
  evaluator.PrepareForEvaluation(true, true);
  residual = 0.0;
  jacobian = {};
  ASSERT_TRUE(evaluate(*wrapper, unseen, &residual, &jacobian));
  EXPECT_EQ(residual, expected_residual);
  EXPECT_EQ(jacobian, expected_jacobian);
  EXPECT_EQ(evaluator.evaluated_directly(), 2);
  EXPECT_EQ(evaluator.replayed(), 0);

  // At kStart itself: replayed, and the same values as the reference there.
  ASSERT_TRUE(evaluate(*reference, kStart, &expected_residual, &expected_jacobian));
  ASSERT_NE(expected_residual, residual);  // the two points differ
  ASSERT_TRUE(evaluate(*wrapper, kStart, &residual, &jacobian));
  EXPECT_EQ(residual, expected_residual);
  EXPECT_EQ(jacobian, expected_jacobian);
  const double* blocks[] = {kStart.data()};
  residual = 0.0;
  ASSERT_TRUE(wrapper->Evaluate(blocks, &residual, nullptr));  // residual only
  EXPECT_EQ(residual, expected_residual);
  EXPECT_EQ(evaluator.evaluated_directly(), 2);
  EXPECT_EQ(evaluator.replayed(), 2);
}

// A wrapped function that fails makes its replaying wrapper fail at that
// point, CostGradient fail, and a Ceres evaluation of the problem fail; the
// other blocks and other points are unaffected.
TEST(ParallelResidualEvaluator, FailureOfAWrappedFunctionIsReplayed) {
  constexpr int kBlocks = 1000;
  constexpr int kFailing = 700;  // in the third thread's chunk
  double x = 2.0;
  ParallelResidualEvaluator evaluator({{&x, 1}}, 3);
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &evaluator;
  ceres::Problem problem(problem_options);
  std::vector<ceres::CostFunction*> wrappers;  // owned by the problem
  for (int i = 0; i < kBlocks; ++i) {
    wrappers.push_back(evaluator.Wrap(new SqrtCost(i == kFailing ? 1.0 : 0.0), {&x}));
    problem.AddResidualBlock(wrappers.back(), nullptr, &x);
  }

  // x = 2: every block evaluates; each adds (1/2)/sqrt(d) * sqrt(d) = 1/2.
  std::vector<double> gradient;
  ASSERT_TRUE(evaluator.CostGradient(&x, &gradient));
  ASSERT_EQ(gradient.size(), 1u);
  EXPECT_NEAR(gradient[0], 0.5 * kBlocks, 1e-9);

  // x = 0.5: block kFailing fails.
  const double half = 0.5;
  EXPECT_FALSE(evaluator.CostGradient(&half, &gradient));
  const double* blocks[] = {&half};
  double residual = 0.0;
  double jacobian = 0.0;
  double* jacobians[] = {&jacobian};
  const std::int64_t replayed = evaluator.replayed();
  EXPECT_FALSE(wrappers[kFailing]->Evaluate(blocks, &residual, jacobians));
  EXPECT_FALSE(wrappers[kFailing]->Evaluate(blocks, &residual, nullptr));
  EXPECT_TRUE(wrappers[0]->Evaluate(blocks, &residual, jacobians));
  EXPECT_EQ(residual, std::sqrt(0.5));
  EXPECT_EQ(evaluator.replayed(), replayed + 3);
  EXPECT_EQ(evaluator.evaluated_directly(), 0);

  // Through Ceres, with the evaluator as the problem's callback.
  double cost = 0.0;
  x = 0.5;
  EXPECT_FALSE(
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr));
  x = 2.0;
  ASSERT_TRUE(
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr));
  EXPECT_NEAR(cost, 0.5 * (2.0 * (kBlocks - 1) + 1.0), 1e-9);
  EXPECT_EQ(evaluator.evaluated_directly(), 0);
}

// Two residuals of {b, c} alone: the cosine's residual and its square.
struct TwoResidualsOfBC {
  explicit TwoResidualsOfBC(const Sample& sample) : cosine(sample) {}
  template <typename T>
  bool operator()(const T* const bc, T* residual) const {
    const T p[3] = {T(kTruth[0]), bc[0], bc[1]};
    if (!cosine(p, residual)) return false;
    residual[1] = residual[0] * residual[0];
    return true;
  }
  DecayingCosine cosine;
};

// Wrapper i of MixedShapeCost: alternately two blocks {a}, {b, c} with one
// residual, and {b, c} alone with two.
ceres::CostFunction* MixedShapeCost(const Sample& sample, int i) {
  if (i % 2 == 0) {
    return new ceres::AutoDiffCostFunction<SplitDecayingCosine, 1, 1, 2>(
        new SplitDecayingCosine(sample));
  }
  return new ceres::AutoDiffCostFunction<TwoResidualsOfBC, 2, 2>(new TwoResidualsOfBC(sample));
}

// Every wrapper replays exactly its own wrapped function's values, residuals
// and Jacobians, whatever the shapes around it, whether room was reserved
// or not, and after wrappers added later have grown the evaluator's storage
// (the values of the earlier ones move with it).
TEST(ParallelResidualEvaluator, WrappersOfMixedShapesReplayTheirOwnValues) {
  constexpr int kFirst = 900;  // wrapped before the first point: three chunks
  constexpr int kLater = 700;  // wrapped after it, growing the storage
  const std::vector<Sample> data = SyntheticData(kFirst + kLater);
  double a[1] = {kStart[0]};
  double bc[2] = {kStart[1], kStart[2]};
  ParallelResidualEvaluator evaluator({{a, 1}, {bc, 2}}, 3);
  evaluator.Reserve(100, 100);  // fewer than wrapped, and of another shape
  std::vector<std::unique_ptr<ceres::CostFunction>> wrappers;
  std::vector<std::unique_ptr<ceres::CostFunction>> references;
  auto wrap = [&](int i) {
    const std::vector<double*> blocks =
        i % 2 == 0 ? std::vector<double*>{a, bc} : std::vector<double*>{bc};
    wrappers.emplace_back(evaluator.Wrap(MixedShapeCost(data[i], i), blocks));
    references.emplace_back(MixedShapeCost(data[i], i));
  };
  // Evaluates wrapper i and its reference at the blocks' values: bitwise equal.
  auto expect_replayed = [&](int i) {
    const bool two_blocks = i % 2 == 0;
    const double* blocks[] = {two_blocks ? a : bc, bc};
    double residuals[2] = {0.0, 0.0};
    double expected_residuals[2] = {1.0, 1.0};
    double jacobian[6] = {0, 0, 0, 0, 0, 0};
    double expected_jacobian[6] = {1, 1, 1, 1, 1, 1};
    double* jacobians[] = {jacobian, jacobian + (two_blocks ? 1 : 4)};
    double* expected_jacobians[] = {expected_jacobian, expected_jacobian + (two_blocks ? 1 : 4)};
    ASSERT_TRUE(wrappers[i]->Evaluate(blocks, residuals, jacobians)) << i;
    ASSERT_TRUE(references[i]->Evaluate(blocks, expected_residuals, expected_jacobians)) << i;
    const int rows = two_blocks ? 1 : 2;
    for (int r = 0; r < rows; ++r) EXPECT_EQ(residuals[r], expected_residuals[r]) << i;
    for (int k = 0; k < (two_blocks ? 3 : 4); ++k)
      EXPECT_EQ(jacobian[k], expected_jacobian[k]) << i;
  };
  for (int i = 0; i < kFirst; ++i) wrap(i);
  evaluator.PrepareForEvaluation(true, true);
  for (int i = kFirst; i < kFirst + kLater; ++i) wrap(i);
  for (int i : {0, 1, 449, 450, kFirst - 1}) expect_replayed(i);
  EXPECT_EQ(evaluator.replayed(), 5);
  EXPECT_EQ(evaluator.evaluated_directly(), 0);

  // A new point: every wrapper, the later ones included, replays it.
  a[0] = 1.7;
  bc[0] = 0.45;
  bc[1] = 1.4;
  evaluator.PrepareForEvaluation(true, true);
  for (int i = 0; i < kFirst + kLater; ++i) expect_replayed(i);
  EXPECT_EQ(evaluator.replayed(), 5 + kFirst + kLater);
  EXPECT_EQ(evaluator.evaluated_directly(), 0);
}

// A positive thread count is itself; 0 is one per processor available, at least 1.
TEST(ParallelResidualEvaluator, ResolveThreadCount) {
  EXPECT_EQ(ResolveThreadCount(3), 3);
  EXPECT_EQ(ResolveThreadCount(1), 1);
  EXPECT_GE(ResolveThreadCount(0), 1);
}

}  // namespace
}  // namespace dwellfit

namespace dwellfit {
namespace {

// The fit of FitWithEvaluator with the wrapped blocks compressed into one
// residual block (ParallelResidualEvaluator::Compress).
Fit FitCompressed(const std::vector<Sample>& data, int num_threads) {
  Fit fit;
  fit.parameters = kStart;
  ParallelResidualEvaluator evaluator({{fit.parameters.data(), 3}}, num_threads);
  std::vector<std::unique_ptr<ceres::CostFunction>> wrappers;
  for (const Sample& sample : data)
    wrappers.emplace_back(evaluator.Wrap(NewDecayingCosine(sample), {fit.parameters.data()}));
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &evaluator;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(evaluator.Compress(), nullptr, fit.parameters.data());
  EXPECT_EQ(problem.NumResiduals(), 3 + 1);
  ceres::Solve(FitOptions(), &problem, &fit.summary);
  fit.replayed = evaluator.replayed();
  fit.evaluated_directly = evaluator.evaluated_directly();
  return fit;
}

// The compressed block's residuals and Jacobian at `point` ({a}, {b, c}).
struct CompressedValues {
  std::vector<double> residuals;
  Eigen::MatrixXd jacobian;  // rows x 3
};

// The residuals and Jacobian of every MixedShapeCost row at `point`, with
// Ceres evaluating the cost functions itself.
void RowsAt(const std::vector<Sample>& data, double a, const double bc[2], Eigen::MatrixXd* j,
            Eigen::VectorXd* r) {
  double a_block = a;
  double bc_block[2] = {bc[0], bc[1]};
  ceres::Problem problem;
  for (size_t i = 0; i < data.size(); ++i) {
    ceres::CostFunction* cost = MixedShapeCost(data[i], static_cast<int>(i));
    if (i % 2 == 0) {
      problem.AddResidualBlock(cost, nullptr, &a_block, bc_block);
    } else {
      problem.AddResidualBlock(cost, nullptr, bc_block);
    }
  }
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = {&a_block, bc_block};
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  ASSERT_TRUE(problem.Evaluate(options, nullptr, &residuals, nullptr, &crs));
  j->setZero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) (*j)(row, crs.cols[k]) = crs.values[k];
  }
  *r = Eigen::Map<const Eigen::VectorXd>(residuals.data(), residuals.size());
}

// The compressed block of MixedShapeCost wrappers, evaluated at (a, bc) on
// `num_threads` threads; one more wrapper made after Compress stays out.
CompressedValues CompressedAt(const std::vector<Sample>& data, double a, const double bc[2],
                              int num_threads) {
  double a_block = a;
  double bc_block[2] = {bc[0], bc[1]};
  ParallelResidualEvaluator evaluator({{&a_block, 1}, {bc_block, 2}}, num_threads);
  std::vector<std::unique_ptr<ceres::CostFunction>> wrappers;
  for (size_t i = 0; i < data.size(); ++i) {
    ceres::CostFunction* cost = MixedShapeCost(data[i], static_cast<int>(i));
    wrappers.emplace_back(i % 2 == 0 ? evaluator.Wrap(cost, {&a_block, bc_block})
                                     : evaluator.Wrap(cost, {bc_block}));
  }
  const std::unique_ptr<ceres::CostFunction> compressed(evaluator.Compress());
  wrappers.emplace_back(evaluator.Wrap(MixedShapeCost(data[1], 1), {bc_block}));
  EXPECT_EQ(compressed->num_residuals(), 4);
  EXPECT_EQ(compressed->parameter_block_sizes(), (std::vector<int32_t>{1, 2}));
  CompressedValues values;
  values.residuals.resize(4);
  double ja[4];
  double jbc[8];
  double* jacobians[] = {ja, jbc};
  const double* blocks[] = {&a_block, bc_block};
  evaluator.PrepareForEvaluation(true, true);
  EXPECT_TRUE(compressed->Evaluate(blocks, values.residuals.data(), jacobians));
  values.jacobian.resize(4, 3);
  for (int row = 0; row < 4; ++row) {
    values.jacobian(row, 0) = ja[row];
    values.jacobian(row, 1) = jbc[2 * row];
    values.jacobian(row, 2) = jbc[2 * row + 1];
  }
  EXPECT_EQ(evaluator.evaluated_directly(), 0);  // the callback's point
  return values;
}

// The compressed block of rows A = [J | r] gives the rows' cost |r|^2/2,
// gradient J^T r and Gauss-Newton matrix J^T J (wrappers of mixed shapes on
// two blocks, several chunks), its last row has no Jacobian, and its values
// are bitwise the same on 1 and 3 threads.
TEST(ParallelResidualEvaluator, CompressedBlockKeepsCostGradientAndGaussNewtonMatrix) {
  const std::vector<Sample> data = SyntheticData(1001);  // 1501 rows: 6 chunks
  const double a = 1.7;
  const double bc[2] = {0.4, 1.4};
  Eigen::MatrixXd j;
  Eigen::VectorXd r;
  RowsAt(data, a, bc, &j, &r);
  ASSERT_EQ(j.rows(), 1501);
  const CompressedValues one = CompressedAt(data, a, bc, 1);
  const Eigen::Map<const Eigen::VectorXd> q(one.residuals.data(), 4);
  EXPECT_NEAR(q.squaredNorm(), r.squaredNorm(), 1e-12 * r.squaredNorm());
  const Eigen::VectorXd gradient = j.transpose() * r;
  EXPECT_LT((one.jacobian.transpose() * q - gradient).norm(), 1e-12 * j.norm() * r.norm());
  const Eigen::MatrixXd gauss_newton = j.transpose() * j;
  EXPECT_LT((one.jacobian.transpose() * one.jacobian - gauss_newton).norm(),
            1e-12 * gauss_newton.norm());
  EXPECT_EQ(one.jacobian.row(3).norm(), 0.0);
  // So the trust-region model |r + J s| is the same for any step s.
  const Eigen::Vector3d step(0.1, -0.2, 0.05);
  EXPECT_NEAR((q + one.jacobian * step).norm(), (r + j * step).norm(), 1e-12 * r.norm());

  const CompressedValues three = CompressedAt(data, a, bc, 3);
  EXPECT_EQ(three.residuals, one.residuals);
  EXPECT_EQ(three.jacobian, one.jacobian);
}

// A solve on the compressed block takes the rows' steps: it ends where the
// solve on the rows ends, in as many iterations, every evaluation answered
// from the callback's values, bitwise the same on 1, 2 and 3 threads.
TEST(ParallelResidualEvaluator, CompressedSolveEndsWhereTheRowsSolveEnds) {
  const std::vector<Sample> data = SyntheticData(kNumSamples);
  const Fit plain = FitWithoutEvaluator(data);
  const Fit one = FitCompressed(data, 1);
  ASSERT_EQ(one.summary.termination_type, ceres::CONVERGENCE) << one.summary.FullReport();
  ASSERT_GT(one.summary.num_successful_steps, 2);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(one.parameters[i], plain.parameters[i], 1e-9 * std::abs(plain.parameters[i])) << i;
  }
  EXPECT_NEAR(one.summary.final_cost, plain.summary.final_cost, 1e-9 * plain.summary.final_cost);
  EXPECT_EQ(one.summary.iterations.size(), plain.summary.iterations.size());
  EXPECT_EQ(one.evaluated_directly, 0);
  EXPECT_GT(one.replayed, 0);
  for (int threads : {2, 3}) {
    const Fit many = FitCompressed(data, threads);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(many.parameters[i], one.parameters[i]) << threads;
    EXPECT_EQ(many.summary.final_cost, one.summary.final_cost) << threads;
  }
}

// r = x^(3/2) - shift, whose Jacobian it reports infinite at x = 0: a row
// with a finite residual and no finite derivative (as a dwell's root at a
// fold). It fails for x < 0.
class InfiniteSlopeAtZero : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit InfiniteSlopeAtZero(double shift) : shift_(shift) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double x = parameters[0][0];
    if (x < 0.0) return false;
    residuals[0] = std::pow(x, 1.5) - shift_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      jacobians[0][0] = x == 0.0 ? std::numeric_limits<double>::infinity() : 1.5 * std::sqrt(x);
    }
    return true;
  }

 private:
  const double shift_;
};

// Where a row's Jacobian is not finite the cost alone is still |r|^2/2
// (Ceres rates a trial point by it) and the Jacobian is not finite (Ceres
// rejects it); where a row fails to evaluate the block fails.
TEST(ParallelResidualEvaluator, CompressedBlockAtAnInfiniteSlopeOrAFailure) {
  double x = 0.0;
  ParallelResidualEvaluator evaluator({{&x, 1}}, 2);
  std::vector<std::unique_ptr<ceres::CostFunction>> wrappers;
  for (int i = 0; i < 600; ++i)
    wrappers.emplace_back(evaluator.Wrap(new InfiniteSlopeAtZero(0.01 * i), {&x}));
  const std::unique_ptr<ceres::CostFunction> compressed(evaluator.Compress());
  double expected = 0.0;
  for (int i = 0; i < 600; ++i) expected += 0.5 * (0.01 * i) * (0.01 * i);
  const double* blocks[] = {&x};
  double residuals[2];
  evaluator.PrepareForEvaluation(false, true);
  ASSERT_TRUE(compressed->Evaluate(blocks, residuals, nullptr));
  EXPECT_NEAR(0.5 * (residuals[0] * residuals[0] + residuals[1] * residuals[1]), expected,
              1e-12 * expected);
  double jacobian[2];
  double* jacobians[] = {jacobian};
  ASSERT_TRUE(compressed->Evaluate(blocks, residuals, jacobians));
  EXPECT_FALSE(std::isfinite(jacobian[0]) && std::isfinite(residuals[0]));

  // A point the callback has not seen is evaluated there.
  const double minus = -1.0;
  const double* failing[] = {&minus};
  EXPECT_FALSE(compressed->Evaluate(failing, residuals, nullptr));
  EXPECT_EQ(evaluator.evaluated_directly(), 1);
  const double one = 1.0;
  const double* at_one[] = {&one};
  ASSERT_TRUE(compressed->Evaluate(at_one, residuals, jacobians));
  double at_one_cost = 0.0;
  for (int i = 0; i < 600; ++i) at_one_cost += 0.5 * (1.0 - 0.01 * i) * (1.0 - 0.01 * i);
  EXPECT_NEAR(0.5 * (residuals[0] * residuals[0] + residuals[1] * residuals[1]), at_one_cost,
              1e-12 * at_one_cost);
  EXPECT_NEAR(jacobian[0] * jacobian[0], 600 * 1.5 * 1.5, 1e-9);  // J^T J
  EXPECT_EQ(jacobian[1], 0.0);
}

}  // namespace
}  // namespace dwellfit
