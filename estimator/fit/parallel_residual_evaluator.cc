#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"

#include <omp.h>

#include <algorithm>

#include "glog/logging.h"

namespace dwellfit {

namespace {

// Blocks each thread gets at the least (fewer threads below that).
constexpr int kMinBlocksPerThread = 256;

}  // namespace

int ResolveThreadCount(int num_threads) {
  if (num_threads > 0) return num_threads;
  // The processors this process may run on (its affinity mask), not every
  // processor of the host.
  return std::max(1, omp_get_num_procs());
}

// Owns one wrapped cost function and the values it had at the last point the
// evaluator saw.
class ParallelResidualEvaluator::ReplayingCostFunction : public ceres::CostFunction {
 public:
  ReplayingCostFunction(ceres::CostFunction* wrapped, int size, ParallelResidualEvaluator* owner)
      : wrapped_(wrapped),
        owner_(owner),
        point_(size),
        residuals_(wrapped->num_residuals()),
        jacobian_(static_cast<size_t>(wrapped->num_residuals()) * size) {
    CHECK_EQ(wrapped->parameter_block_sizes().size(), 1u);
    CHECK_EQ(wrapped->parameter_block_sizes()[0], size);
    set_num_residuals(wrapped->num_residuals());
    *mutable_parameter_block_sizes() = wrapped->parameter_block_sizes();
  }

  // Adds J^T r at the precomputed point to `gradient`; false if the
  // evaluation failed.
  bool AddGradient(double* gradient) const {
    if (!ok_) return false;
    const int size = static_cast<int>(point_.size());
    for (size_t row = 0; row < residuals_.size(); ++row) {
      for (int col = 0; col < size; ++col)
        gradient[col] += jacobian_[row * size + col] * residuals_[row];
    }
    return true;
  }

  // Computes the values at `point` (the evaluator's thread for this block).
  void Precompute(const double* point) {
    std::copy(point, point + point_.size(), point_.begin());
    const double* blocks[] = {point};
    double* jacobians[] = {jacobian_.data()};
    ok_ = wrapped_->Evaluate(blocks, residuals_.data(), jacobians);
    valid_ = true;
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (!valid_ || !std::equal(point_.begin(), point_.end(), parameters[0])) {
      ++owner_->evaluated_directly_;
      return wrapped_->Evaluate(parameters, residuals, jacobians);
    }
    ++owner_->replayed_;
    if (!ok_) return false;
    std::copy(residuals_.begin(), residuals_.end(), residuals);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      std::copy(jacobian_.begin(), jacobian_.end(), jacobians[0]);
    }
    return true;
  }

 private:
  const std::unique_ptr<ceres::CostFunction> wrapped_;
  ParallelResidualEvaluator* const owner_;
  std::vector<double> point_;
  std::vector<double> residuals_;
  std::vector<double> jacobian_;  // row-major, num_residuals x size
  bool ok_ = false;
  bool valid_ = false;
};

ParallelResidualEvaluator::ParallelResidualEvaluator(const double* parameters, int size,
                                                     int num_threads)
    : parameters_(parameters), size_(size), num_threads_(num_threads) {
  CHECK(parameters != nullptr);
  CHECK_GT(size, 0);
  CHECK_GE(num_threads, 1);
}

ParallelResidualEvaluator::~ParallelResidualEvaluator() = default;

ceres::CostFunction* ParallelResidualEvaluator::Wrap(ceres::CostFunction* cost_function) {
  auto* wrapper = new ReplayingCostFunction(cost_function, size_, this);
  wrappers_.push_back(wrapper);
  return wrapper;
}

void ParallelResidualEvaluator::PrepareForEvaluation(bool /*evaluate_jacobians*/,
                                                     bool /*new_evaluation_point*/) {
  // Ceres has copied the point into the caller's block. The same point again
  // (the Jacobian at an accepted step, a line search's trial step and the
  // trust-region candidate): the values, Jacobians included, are there.
  if (computed_ && std::equal(last_point_.begin(), last_point_.end(), parameters_)) return;
  PrecomputeAll(parameters_);
}

void ParallelResidualEvaluator::PrecomputeAll(const double* point) {
  // Every thread reads this one copy of the point.
  last_point_.assign(point, point + size_);
  computed_ = true;
  const double* copy = last_point_.data();
  const int count = static_cast<int>(wrappers_.size());
  // A parallel region costs microseconds: threads only for enough blocks.
  const int threads = std::max(1, std::min(num_threads_, count / kMinBlocksPerThread));
  // schedule(static): fixed contiguous chunks, one per thread.
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
  for (int i = 0; i < count; ++i) wrappers_[i]->Precompute(copy);
}

bool ParallelResidualEvaluator::CostGradient(const double* point, std::vector<double>* gradient) {
  PrecomputeAll(point);
  gradient->assign(size_, 0.0);
  for (const ReplayingCostFunction* wrapper : wrappers_) {
    if (!wrapper->AddGradient(gradient->data())) return false;
  }
  return true;
}

}  // namespace dwellfit
