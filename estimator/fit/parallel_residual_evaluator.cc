#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"

#include <omp.h>

#include <algorithm>
#include <utility>

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
  // `offsets`: where each of the wrapped function's parameter blocks starts
  // in the evaluator's point.
  ReplayingCostFunction(ceres::CostFunction* wrapped, std::vector<int> offsets,
                        ParallelResidualEvaluator* owner)
      : wrapped_(wrapped), owner_(owner), offsets_(std::move(offsets)) {
    const std::vector<int32_t>& sizes = wrapped->parameter_block_sizes();
    CHECK_EQ(sizes.size(), offsets_.size());
    set_num_residuals(wrapped->num_residuals());
    *mutable_parameter_block_sizes() = sizes;
    const int rows = wrapped->num_residuals();
    int total = 0;
    for (int size : sizes) {
      starts_.push_back(total);
      total += size;
    }
    point_.resize(total);
    residuals_.resize(rows);
    jacobian_.resize(static_cast<size_t>(rows) * total);
    for (size_t j = 0; j < sizes.size(); ++j) {
      block_pointers_.push_back(point_.data() + starts_[j]);
      jacobian_pointers_.push_back(jacobian_.data() + static_cast<size_t>(rows) * starts_[j]);
    }
  }

  // Adds J^T r at the precomputed point to `gradient` (a point's
  // coordinates); false if the evaluation failed.
  bool AddGradient(double* gradient) const {
    if (!ok_) return false;
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    for (size_t j = 0; j < sizes.size(); ++j) {
      const double* jacobian = jacobian_pointers_[j];
      for (size_t row = 0; row < residuals_.size(); ++row) {
        for (int col = 0; col < sizes[j]; ++col)
          gradient[offsets_[j] + col] += jacobian[row * sizes[j] + col] * residuals_[row];
      }
    }
    return true;
  }

  // Computes the values at `point` (the evaluator's thread for this block).
  void Precompute(const double* point) {
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    for (size_t j = 0; j < sizes.size(); ++j) {
      std::copy(point + offsets_[j], point + offsets_[j] + sizes[j], point_.begin() + starts_[j]);
    }
    ok_ = wrapped_->Evaluate(block_pointers_.data(), residuals_.data(), jacobian_pointers_.data());
    valid_ = true;
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (!valid_ || !AtPoint(parameters)) {
      ++owner_->evaluated_directly_;
      return wrapped_->Evaluate(parameters, residuals, jacobians);
    }
    ++owner_->replayed_;
    if (!ok_) return false;
    std::copy(residuals_.begin(), residuals_.end(), residuals);
    if (jacobians == nullptr) return true;
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    for (size_t j = 0; j < sizes.size(); ++j) {
      if (jacobians[j] == nullptr) continue;
      std::copy(jacobian_pointers_[j], jacobian_pointers_[j] + residuals_.size() * sizes[j],
                jacobians[j]);
    }
    return true;
  }

 private:
  // `parameters` are the precomputed point.
  bool AtPoint(double const* const* parameters) const {
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    for (size_t j = 0; j < sizes.size(); ++j) {
      const double* own = point_.data() + starts_[j];
      if (!std::equal(own, own + sizes[j], parameters[j])) return false;
    }
    return true;
  }

  const std::unique_ptr<ceres::CostFunction> wrapped_;
  ParallelResidualEvaluator* const owner_;
  const std::vector<int> offsets_;  // of each parameter block in the evaluator's point
  std::vector<int> starts_;         // of each parameter block in point_
  std::vector<double> point_;       // the point the values are for, its blocks concatenated
  std::vector<double> residuals_;
  std::vector<double> jacobian_;  // per parameter block: row-major, num_residuals x its size
  std::vector<const double*> block_pointers_;  // into point_
  std::vector<double*> jacobian_pointers_;     // into jacobian_
  bool ok_ = false;
  bool valid_ = false;
};

ParallelResidualEvaluator::ParallelResidualEvaluator(std::vector<Block> blocks, int num_threads)
    : blocks_(std::move(blocks)), num_threads_(num_threads) {
  CHECK(!blocks_.empty());
  for (const Block& block : blocks_) {
    CHECK(block.values != nullptr);
    CHECK_GT(block.size, 0);
    offsets_.push_back(size_);
    size_ += block.size;
  }
  CHECK_GE(num_threads, 1);
}

ParallelResidualEvaluator::ParallelResidualEvaluator(const double* parameters, int size,
                                                     int num_threads)
    : ParallelResidualEvaluator(std::vector<Block>{{parameters, size}}, num_threads) {}

ParallelResidualEvaluator::~ParallelResidualEvaluator() = default;

ceres::CostFunction* ParallelResidualEvaluator::Wrap(ceres::CostFunction* cost_function,
                                                     const std::vector<double*>& parameter_blocks) {
  CHECK_EQ(cost_function->parameter_block_sizes().size(), parameter_blocks.size());
  std::vector<int> offsets;
  for (size_t j = 0; j < parameter_blocks.size(); ++j) {
    size_t b = 0;
    while (b < blocks_.size() && blocks_[b].values != parameter_blocks[j]) ++b;
    CHECK_LT(b, blocks_.size()) << "a parameter block the evaluator does not watch";
    CHECK_EQ(cost_function->parameter_block_sizes()[j], blocks_[b].size);
    offsets.push_back(offsets_[b]);
  }
  auto* wrapper = new ReplayingCostFunction(cost_function, std::move(offsets), this);
  wrappers_.push_back(wrapper);
  return wrapper;
}

ceres::CostFunction* ParallelResidualEvaluator::Wrap(ceres::CostFunction* cost_function) {
  return Wrap(cost_function, {const_cast<double*>(blocks_[0].values)});
}

bool ParallelResidualEvaluator::AtLastPoint() const {
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const double* last = last_point_.data() + offsets_[b];
    if (!std::equal(last, last + blocks_[b].size, blocks_[b].values)) return false;
  }
  return true;
}

void ParallelResidualEvaluator::PrepareForEvaluation(bool /*evaluate_jacobians*/,
                                                     bool /*new_evaluation_point*/) {
  // Ceres has copied the point into the caller's blocks. The same point
  // again (the Jacobian at an accepted step, a line search's trial step and
  // the trust-region candidate): the values, Jacobians included, are there.
  if (computed_ && AtLastPoint()) return;
  last_point_.resize(size_);
  for (size_t b = 0; b < blocks_.size(); ++b) {
    std::copy(blocks_[b].values, blocks_[b].values + blocks_[b].size,
              last_point_.begin() + offsets_[b]);
  }
  PrecomputeAll();
}

void ParallelResidualEvaluator::PrecomputeAll() {
  // Every thread reads this one copy of the point.
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
  last_point_.assign(point, point + size_);
  PrecomputeAll();
  gradient->assign(size_, 0.0);
  for (const ReplayingCostFunction* wrapper : wrappers_) {
    if (!wrapper->AddGradient(gradient->data())) return false;
  }
  return true;
}

}  // namespace dwellfit
