#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"

#include <sched.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

#include "Eigen/QR"
#include "glog/logging.h"

namespace dwellfit {

int ResolveThreadCount(int num_threads) {
  if (num_threads > 0) return num_threads;
  // The processors this process may run on (its affinity mask), not every
  // processor of the host.
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof(allowed), &allowed) == 0) return std::max(1, CPU_COUNT(&allowed));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// The threads beside the caller's that run an evaluation's units with it,
// each unit to whichever thread asks next. A thread without work sleeps at
// once, without spinning, so that a program sharing its core gets the
// processor back (TBB's workers spin first; docs/performance.md).
class ParallelResidualEvaluator::Workers {
 public:
  explicit Workers(int threads) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Serve(); });
  }
  ~Workers() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& thread : threads_) thread.join();
  }

  // run(unit) for every unit in [0, units), each once, on the caller and
  // the threads; returns when every unit has run.
  void Run(int units, const std::function<void(int)>& run) {
    auto batch = std::make_shared<Batch>();
    batch->units = units;
    batch->run = &run;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      batch_ = batch;
      ++generation_;
    }
    wake_.notify_all();
    Work(batch.get());
    // Wait for the units still running: spinning, after about 1 ms asleep.
    int spins = 0;
    while (batch->done.load() < units && ++spins < kCallerSpins) {
    }
    std::unique_lock<std::mutex> lock(batch->mutex);
    batch->finished.wait(lock, [&] { return batch->done.load() == units; });
  }

 private:
  // One evaluation's units: the next to hand out, and those that have run.
  struct Batch {
    std::atomic<int> next{0};
    std::atomic<int> done{0};
    int units = 0;
    const std::function<void(int)>* run = nullptr;  // called only while units remain
    std::mutex mutex;
    std::condition_variable finished;
  };

  static void Work(Batch* batch) {
    for (int unit = batch->next++; unit < batch->units; unit = batch->next++) {
      (*batch->run)(unit);
      if (++batch->done == batch->units) {
        const std::lock_guard<std::mutex> lock(batch->mutex);
        batch->finished.notify_all();
      }
    }
  }

  void Serve() {
    std::uint64_t seen = 0;
    for (;;) {
      std::shared_ptr<Batch> batch;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        batch = batch_;
      }
      Work(batch.get());
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::shared_ptr<Batch> batch_;  // the last evaluation's
  std::uint64_t generation_ = 0;  // evaluations handed out
  bool stop_ = false;
  // Checks of the units done before the caller sleeps.
  static constexpr int kCallerSpins = 1000000;
  std::vector<std::thread> threads_;
};

// Owns one wrapped cost function. Its values at the evaluator's last point
// live in the evaluator's storage_: the point (its parameter blocks
// concatenated), residuals, and Jacobian (per block, row-major). Where its
// blocks start in the evaluator's point: block_offsets_ from first_offset_.
class ParallelResidualEvaluator::ReplayingCostFunction : public ceres::CostFunction {
 public:
  // `offsets`: where each of the wrapped function's parameter blocks starts
  // in the evaluator's point.
  ReplayingCostFunction(ceres::CostFunction* wrapped, const std::vector<int>& offsets,
                        ParallelResidualEvaluator* owner)
      : wrapped_(wrapped), owner_(owner) {
    CHECK_EQ(wrapped->parameter_block_sizes().size(), offsets.size());
    CHECK_LE(offsets.size(), kMaxBlocks);
    set_num_residuals(wrapped->num_residuals());
    *mutable_parameter_block_sizes() = wrapped->parameter_block_sizes();
    rows_ = wrapped->num_residuals();
    for (int size : parameter_block_sizes()) total_ += size;
    first_offset_ = owner->block_offsets_.size();
    owner->block_offsets_.insert(owner->block_offsets_.end(), offsets.begin(), offsets.end());
    storage_offset_ = owner->storage_.size();
    owner->storage_.resize(storage_offset_ + static_cast<size_t>(total_) * (1 + rows_) + rows_);
  }

  // Adds J^T r at the precomputed point to `gradient` (a point's
  // coordinates); false if the evaluation failed.
  bool AddGradient(double* gradient) const {
    if (!ok_) return false;
    ForEachJacobianEntry(
        [&](int row, int column, double value) { gradient[column] += value * Residuals()[row]; });
    return true;
  }

  // Writes the precomputed Jacobian into `a`'s point columns and the
  // residuals into its last, from row `row` on; false if the evaluation failed.
  bool WriteRows(Eigen::MatrixXd* a, int row) const {
    if (!ok_) return false;
    ForEachJacobianEntry([&](int i, int column, double value) { (*a)(row + i, column) = value; });
    for (int i = 0; i < rows_; ++i) (*a)(row + i, a->cols() - 1) = Residuals()[i];
    return true;
  }

  // |r|^2 at the precomputed point.
  double SquaredNorm() const {
    double sum = 0.0;
    for (int i = 0; i < rows_; ++i) sum += Residuals()[i] * Residuals()[i];
    return sum;
  }

  int rows() const { return rows_; }

  // Computes the values at `point` (on the evaluator's threads).
  void Precompute(const double* point) {
    valid_ = true;
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    std::array<const double*, kMaxBlocks> blocks;
    std::array<double*, kMaxBlocks> jacobians;
    int start = 0;
    for (size_t j = 0; j < sizes.size(); ++j) {
      std::copy(point + Offset(j), point + Offset(j) + sizes[j], Point() + start);
      blocks[j] = Point() + start;
      jacobians[j] = Jacobian() + rows_ * start;
      start += sizes[j];
    }
    ok_ = wrapped_->Evaluate(blocks.data(), Residuals(), jacobians.data());
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (!valid_ || !AtPoint(parameters)) {
      ++owner_->evaluated_directly_;
      return wrapped_->Evaluate(parameters, residuals, jacobians);
    }
    ++owner_->replayed_;
    if (!ok_) return false;
    std::copy(Residuals(), Residuals() + rows_, residuals);
    if (jacobians == nullptr) return true;
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    int start = 0;
    for (size_t j = 0; j < sizes.size(); ++j) {
      const double* jacobian = Jacobian() + rows_ * start;
      if (jacobians[j] != nullptr) std::copy(jacobian, jacobian + rows_ * sizes[j], jacobians[j]);
      start += sizes[j];
    }
    return true;
  }

 private:
  // Calls visit(row, column, value) for every entry of the precomputed
  // Jacobian, `column` the entry's place in the evaluator's point.
  template <typename Visit>
  void ForEachJacobianEntry(Visit visit) const {
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    int start = 0;
    for (size_t j = 0; j < sizes.size(); ++j) {
      const double* jacobian = Jacobian() + rows_ * start;
      for (int row = 0; row < rows_; ++row) {
        for (int col = 0; col < sizes[j]; ++col) {
          visit(row, Offset(j) + col, jacobian[row * sizes[j] + col]);
        }
      }
      start += sizes[j];
    }
  }

  // Parameter blocks at the most (every dwellfit residual reads at most six).
  static constexpr size_t kMaxBlocks = 8;

  // Where the wrapped function's parameter block j starts in the evaluator's point.
  int Offset(size_t j) const { return owner_->block_offsets_[first_offset_ + j]; }
  // In owner_->storage_, which const evaluations read and Precompute writes.
  double* Point() const { return owner_->storage_.data() + storage_offset_; }
  double* Residuals() const { return Point() + total_; }
  double* Jacobian() const { return Point() + total_ + rows_; }

  // `parameters` are the precomputed point.
  bool AtPoint(double const* const* parameters) const {
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    int start = 0;
    for (size_t j = 0; j < sizes.size(); ++j) {
      if (!std::equal(Point() + start, Point() + start + sizes[j], parameters[j])) return false;
      start += sizes[j];
    }
    return true;
  }

  const std::unique_ptr<ceres::CostFunction> wrapped_;
  ParallelResidualEvaluator* const owner_;
  size_t storage_offset_ = 0;  // of the point, residuals and Jacobian in owner_->storage_
  size_t first_offset_ = 0;    // of the blocks' offsets in owner_->block_offsets_
  int rows_ = 0;               // residuals
  int total_ = 0;              // doubles over the parameter blocks
  bool ok_ = false;
  bool valid_ = false;
};

template <typename Values>
bool ParallelResidualEvaluator::AtLastPoint(const Values& values) const {
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const double* last = last_point_.data() + offsets_[b];
    if (!std::equal(last, last + blocks_[b].size, values(b))) return false;
  }
  return true;
}

template <typename Values>
void ParallelResidualEvaluator::CopyToPoint(const Values& values,
                                            std::vector<double>* point) const {
  point->resize(size_);
  for (size_t b = 0; b < blocks_.size(); ++b) {
    std::copy(values(b), values(b) + blocks_[b].size, point->begin() + offsets_[b]);
  }
}

// The one residual block of the compressed wrappers (Compress).
class ParallelResidualEvaluator::CompressedCostFunction : public ceres::CostFunction {
 public:
  explicit CompressedCostFunction(ParallelResidualEvaluator* owner) : owner_(owner) {
    set_num_residuals(owner->size_ + 1);
    for (const Block& block : owner->blocks_)
      mutable_parameter_block_sizes()->push_back(block.size);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return owner_->EvaluateCompressed(parameters, residuals, jacobians);
  }

 private:
  ParallelResidualEvaluator* const owner_;
};

ParallelResidualEvaluator::ParallelResidualEvaluator(std::vector<Block> blocks, int num_threads,
                                                     int min_rows_per_thread)
    : blocks_(std::move(blocks)),
      num_threads_(num_threads),
      min_rows_per_thread_(min_rows_per_thread) {
  CHECK(!blocks_.empty());
  for (const Block& block : blocks_) {
    CHECK(block.values != nullptr);
    CHECK_GT(block.size, 0);
    offsets_.push_back(size_);
    size_ += block.size;
  }
  CHECK_GE(num_threads, 1);
  CHECK_GE(min_rows_per_thread, 1);
  CopyToPoint(BlockValues(), &iterate_);  // sized once: IterateEntry hands out pointers into it
}

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
  auto* wrapper = new ReplayingCostFunction(cost_function, offsets, this);
  wrappers_.push_back(wrapper);
  rows_ += cost_function->num_residuals();
  return wrapper;
}

void ParallelResidualEvaluator::Reserve(int wrappers, int residuals) {
  wrappers_.reserve(wrappers_.size() + wrappers);
  block_offsets_.reserve(block_offsets_.size() + wrappers);
  // Per wrapper its point; per residual its value and Jacobian row.
  storage_.reserve(storage_.size() + static_cast<size_t>(wrappers) * size_ +
                   static_cast<size_t>(residuals) * (1 + size_));
}

const double* ParallelResidualEvaluator::IterateEntry(const double* value) const {
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const double* begin = blocks_[b].values;
    if (value >= begin && value < begin + blocks_[b].size) {
      return iterate_.data() + offsets_[b] + (value - begin);
    }
  }
  return nullptr;
}

void ParallelResidualEvaluator::PrepareForEvaluation(bool evaluate_jacobians,
                                                     bool /*new_evaluation_point*/) {
  // Ceres has copied the point into the caller's blocks; at the same point
  // again the values, Jacobians included, are there.
  if (!computed_ || !AtLastPoint(BlockValues())) {
    CopyToPoint(BlockValues(), &last_point_);
    PrecomputeAll();
  }
  if (evaluate_jacobians) std::copy(last_point_.begin(), last_point_.end(), iterate_.begin());
}

void ParallelResidualEvaluator::PrecomputeAll() {
  // Every thread reads this one copy of the point.
  computed_ = true;
  const double* copy = last_point_.data();
  const int chunks = static_cast<int>(chunk_ends_.size());
  const int units = chunks + static_cast<int>(wrappers_.size()) - compressed_;
  // Handing work to a thread costs microseconds: threads only for enough rows.
  const int threads = std::max(1, std::min({num_threads_, units, rows_ / min_rows_per_thread_}));
  if (threads == 1) {
    for (int unit = 0; unit < units; ++unit) PrecomputeUnit(unit, copy);
  } else {
    // Units are single, so a worker the machine runs slowly holds up one.
    if (workers_ == nullptr) workers_ = std::make_unique<Workers>(num_threads_ - 1);
    workers_->Run(units, [this, copy](int unit) { PrecomputeUnit(unit, copy); });
  }
  if (chunks > 0) CombineChunks();
}

void ParallelResidualEvaluator::PrecomputeUnit(int unit, const double* point) {
  const int chunks = static_cast<int>(chunk_ends_.size());
  if (unit >= chunks) {
    wrappers_[compressed_ + unit - chunks]->Precompute(point);
    return;
  }
  const int first = unit == 0 ? 0 : chunk_ends_[unit - 1];
  for (int i = first; i < chunk_ends_[unit]; ++i) wrappers_[i]->Precompute(point);
  FactorChunk(unit);
}

void ParallelResidualEvaluator::FactorChunk(int chunk) {
  const int first = chunk == 0 ? 0 : chunk_ends_[chunk - 1];
  int rows = 0;
  for (int i = first; i < chunk_ends_[chunk]; ++i) rows += wrappers_[i]->rows();
  const int width = size_ + 1;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rows, width);
  bool ok = true;
  int row = 0;
  for (int i = first; i < chunk_ends_[chunk] && ok; ++i) {
    ok = wrappers_[i]->WriteRows(&a, row);
    row += wrappers_[i]->rows();
  }
  chunk_ok_[chunk] = ok;
  if (!ok) return;
  const Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(a);  // in place
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> r(
      chunk_r_.data() + static_cast<size_t>(chunk) * width * width, width, width);
  r.setZero();
  const int kept = std::min(rows, width);
  r.topRows(kept) = a.topRows(kept).triangularView<Eigen::Upper>();
}

void ParallelResidualEvaluator::CombineChunks() {
  const int chunks = static_cast<int>(chunk_ends_.size());
  compressed_ok_ = std::all_of(chunk_ok_.begin(), chunk_ok_.end(), [](char ok) { return ok; });
  if (!compressed_ok_) return;
  const int width = size_ + 1;
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
      stacked(chunk_r_.data(), static_cast<Eigen::Index>(chunks) * width, width);
  if (chunks == 1) {
    compressed_r_ = stacked;
    return;
  }
  Eigen::MatrixXd a = stacked;
  const Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(a);  // in place
  compressed_r_ = a.topRows(width).triangularView<Eigen::Upper>();
}

ceres::CostFunction* ParallelResidualEvaluator::Compress() {
  CHECK_EQ(compressed_, 0) << "Compress() once";
  CHECK(!wrappers_.empty());
  compressed_ = static_cast<int>(wrappers_.size());
  int rows = 0;
  for (int i = 0; i < compressed_; ++i) {
    rows += wrappers_[i]->rows();
    if (rows >= kCompressedChunkRows || i + 1 == compressed_) {
      chunk_ends_.push_back(i + 1);
      rows = 0;
    }
  }
  const size_t width = size_ + 1;
  chunk_r_.assign(chunk_ends_.size() * width * width, 0.0);
  chunk_ok_.assign(chunk_ends_.size(), false);
  computed_ = false;
  return new CompressedCostFunction(this);
}

bool ParallelResidualEvaluator::EvaluateCompressed(double const* const* parameters,
                                                   double* residuals, double** jacobians) {
  const auto values = [parameters](size_t b) { return parameters[b]; };
  if (computed_ && AtLastPoint(values)) {
    ++replayed_;
  } else {  // a point the callback did not see
    ++evaluated_directly_;
    CopyToPoint(values, &last_point_);
    PrecomputeAll();
  }
  if (!compressed_ok_) return false;
  const int width = size_ + 1;
  for (int i = 0; i < width; ++i) residuals[i] = compressed_r_(i, size_);
  if (jacobians == nullptr) {
    // The cost alone: a Jacobian that is not finite (a dwell at a fold)
    // spoils q and rho, not |r|.
    if (compressed_r_.col(size_).allFinite()) return true;
    double sum = 0.0;
    for (int i = 0; i < compressed_; ++i) sum += wrappers_[i]->SquaredNorm();
    std::fill(residuals, residuals + width, 0.0);
    residuals[size_] = std::sqrt(sum);
    return true;
  }
  for (size_t b = 0; b < blocks_.size(); ++b) {
    if (jacobians[b] == nullptr) continue;
    for (int i = 0; i < width; ++i) {
      for (int col = 0; col < blocks_[b].size; ++col) {
        jacobians[b][i * blocks_[b].size + col] = compressed_r_(i, offsets_[b] + col);
      }
    }
  }
  return true;
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
