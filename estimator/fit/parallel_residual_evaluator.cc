#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"

#include <sched.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <thread>
#include <utility>

#include "glog/logging.h"
#include "tbb/blocked_range.h"
#include "tbb/parallel_for.h"

namespace dwellfit {

namespace {

// Residuals (dwells) each thread gets at the least (fewer threads below that).
constexpr int kMinRowsPerThread = 256;

// What this process's evaluators of one kind (ParallelResidualEvaluator's
// `kind`) last found, for the next of that kind to go on from: which way
// (threaded or in the caller alone) was faster (0: none has compared them
// yet, 1: threaded, 2: alone), how many evaluations its trials of the other
// way had come to wait, and how many had run since its last trial. Only a
// preference: no value depends on it.
struct KindHistory {
  std::atomic<int> faster_way{0};
  std::atomic<int> trial_interval{0};
  std::atomic<int> since_trial{0};
};
KindHistory histories[ParallelResidualEvaluator::kKinds];
// Whether a threaded evaluation has run in this process (the first starts
// TBB's worker threads, and its time says nothing about the ways).
std::atomic<bool> workers_started{false};
// The threads are chosen only where their evaluations are this much faster:
// a threaded evaluation also costs time outside itself (the workers that
// wake, and that look for more work before they sleep, take processor time
// from the caller's serial work on a busy machine).
constexpr double kThreadedMargin = 1.3;

}  // namespace

int ResolveThreadCount(int num_threads) {
  if (num_threads > 0) return num_threads;
  // The processors this process may run on (its affinity mask), not every
  // processor of the host. Asked of the kernel: TBB's answer first maps the
  // machine's topology, loading libraries for it (some 1.5 ms of a process
  // whose fit takes one).
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof(allowed), &allowed) == 0) return std::max(1, CPU_COUNT(&allowed));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// Owns one wrapped cost function. The values it had at the last point the
// evaluator saw live in the evaluator's storage_, contiguous per wrapper and
// wrappers in order (no allocation of their own): the point (the wrapped
// function's parameter blocks concatenated), its residuals, and its Jacobian
// (per parameter block, row-major, num_residuals x the block's size). Where
// each of its parameter blocks starts in the evaluator's point is in the
// evaluator's block_offsets_, from first_offset_ on.
class ParallelResidualEvaluator::ReplayingCostFunction : public ceres::CostFunction {
 public:
  // `offsets`: where each of the wrapped function's parameter blocks starts
  // in the evaluator's point. Appends the wrapper's offsets and storage to
  // the evaluator's.
  ReplayingCostFunction(ceres::CostFunction* wrapped, const std::vector<int>& offsets,
                        ParallelResidualEvaluator* owner)
      : wrapped_(wrapped), owner_(owner) {
    CHECK_EQ(wrapped->parameter_block_sizes().size(), offsets.size());
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
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    int start = 0;
    for (size_t j = 0; j < sizes.size(); ++j) {
      const double* jacobian = Jacobian() + rows_ * start;
      for (int row = 0; row < rows_; ++row) {
        for (int col = 0; col < sizes[j]; ++col)
          gradient[Offset(j) + col] += jacobian[row * sizes[j] + col] * Residuals()[row];
      }
      start += sizes[j];
    }
    return true;
  }

  // Computes the values at `point` (the evaluator's thread for this block).
  void Precompute(const double* point) {
    valid_ = true;
    if (NumBlocks() == 1) {  // one parameter block: no per-block bookkeeping
      std::copy(point + Offset(0), point + Offset(0) + total_, Point());
      const double* blocks[] = {Point()};
      double* jacobians[] = {Jacobian()};
      ok_ = wrapped_->Evaluate(blocks, Residuals(), jacobians);
      return;
    }
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    int start = 0;
    for (size_t j = 0; j < sizes.size(); ++j) {
      std::copy(point + Offset(j), point + Offset(j) + sizes[j], Point() + start);
      start += sizes[j];
    }
    ok_ = EvaluateAtOwnPoint();
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (NumBlocks() == 1) return EvaluateOneBlock(parameters, residuals, jacobians);
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
  // Parameter blocks whose pointers fit on the stack (every dwellfit
  // residual reads at most six).
  static constexpr size_t kStackBlocks = 8;

  size_t NumBlocks() const { return parameter_block_sizes().size(); }
  // Where the wrapped function's parameter block j starts in the evaluator's point.
  int Offset(size_t j) const { return owner_->block_offsets_[first_offset_ + j]; }
  double* Point() { return owner_->storage_.data() + storage_offset_; }
  const double* Point() const { return owner_->storage_.data() + storage_offset_; }
  double* Residuals() { return Point() + total_; }
  const double* Residuals() const { return Point() + total_; }
  double* Jacobian() { return Point() + total_ + rows_; }
  const double* Jacobian() const { return Point() + total_ + rows_; }

  // The wrapped function at Point(), into Residuals() and Jacobian().
  bool EvaluateAtOwnPoint() {
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    std::array<const double*, kStackBlocks> block_array;
    std::array<double*, kStackBlocks> jacobian_array;
    std::vector<const double*> block_vector;
    std::vector<double*> jacobian_vector;
    const double** blocks = block_array.data();
    double** jacobians = jacobian_array.data();
    if (sizes.size() > kStackBlocks) {
      block_vector.resize(sizes.size());
      jacobian_vector.resize(sizes.size());
      blocks = block_vector.data();
      jacobians = jacobian_vector.data();
    }
    int start = 0;
    for (size_t j = 0; j < sizes.size(); ++j) {
      blocks[j] = Point() + start;
      jacobians[j] = Jacobian() + rows_ * start;
      start += sizes[j];
    }
    return wrapped_->Evaluate(blocks, Residuals(), jacobians);
  }

  // Evaluate for a function of one parameter block (every dwell on one
  // 6-double block): the same, without the per-block bookkeeping.
  bool EvaluateOneBlock(double const* const* parameters, double* residuals,
                        double** jacobians) const {
    if (!valid_ || !std::equal(Point(), Point() + total_, parameters[0])) {
      ++owner_->evaluated_directly_;
      return wrapped_->Evaluate(parameters, residuals, jacobians);
    }
    ++owner_->replayed_;
    if (!ok_) return false;
    std::copy(Residuals(), Residuals() + rows_, residuals);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      std::copy(Jacobian(), Jacobian() + rows_ * total_, jacobians[0]);
    }
    return true;
  }

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

ParallelResidualEvaluator::ParallelResidualEvaluator(std::vector<Block> blocks, int num_threads,
                                                     int kind)
    : blocks_(std::move(blocks)), num_threads_(num_threads), kind_(kind), arena_(num_threads) {
  CHECK(!blocks_.empty());
  for (const Block& block : blocks_) {
    CHECK(block.values != nullptr);
    CHECK_GT(block.size, 0);
    offsets_.push_back(size_);
    size_ += block.size;
  }
  CHECK_GE(num_threads, 1);
  CHECK(kind >= 0 && kind < kKinds);
  const KindHistory& history = histories[kind];
  const int way = history.faster_way.load(std::memory_order_relaxed);
  prefer_threaded_ = way != 2;
  probe_interval_ = way == 0 ? 3 : history.trial_interval.load(std::memory_order_relaxed);
  since_probe_ = way == 0 ? 0 : history.since_trial.load(std::memory_order_relaxed);
  CopyBlocksTo(&iterate_);  // sized once: IterateEntry hands out pointers into it
}

ParallelResidualEvaluator::ParallelResidualEvaluator(const double* parameters, int size,
                                                     int num_threads, int kind)
    : ParallelResidualEvaluator(std::vector<Block>{{parameters, size}}, num_threads, kind) {}

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

ceres::CostFunction* ParallelResidualEvaluator::Wrap(ceres::CostFunction* cost_function) {
  CHECK_EQ(cost_function->parameter_block_sizes().size(), 1u);
  CHECK_EQ(cost_function->parameter_block_sizes()[0], blocks_[0].size);
  auto* wrapper = new ReplayingCostFunction(cost_function, {0}, this);
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

void ParallelResidualEvaluator::CopyBlocksTo(std::vector<double>* point) const {
  point->resize(size_);
  for (size_t b = 0; b < blocks_.size(); ++b) {
    std::copy(blocks_[b].values, blocks_[b].values + blocks_[b].size, point->begin() + offsets_[b]);
  }
}

bool ParallelResidualEvaluator::AtLastPoint() const {
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const double* last = last_point_.data() + offsets_[b];
    if (!std::equal(last, last + blocks_[b].size, blocks_[b].values)) return false;
  }
  return true;
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
  // Ceres has copied the point into the caller's blocks. The same point
  // again (the Jacobian at an accepted step, a line search's trial step and
  // the trust-region candidate): the values, Jacobians included, are there.
  if (!computed_ || !AtLastPoint()) {
    CopyBlocksTo(&last_point_);
    PrecomputeAll();
  }
  // last_point_ now holds the caller's blocks either way.
  if (evaluate_jacobians) std::copy(last_point_.begin(), last_point_.end(), iterate_.begin());
}

void ParallelResidualEvaluator::PrecomputeAll() {
  // Every thread reads this one copy of the point.
  computed_ = true;
  const double* copy = last_point_.data();
  const int count = static_cast<int>(wrappers_.size());
  // Handing work to a thread costs microseconds: threads only for enough rows.
  const int threads = std::max(1, std::min({num_threads_, count, rows_ / kMinRowsPerThread}));
  if (threads == 1) {
    for (int i = 0; i < count; ++i) wrappers_[i]->Precompute(copy);
    return;
  }
  const bool threaded = ChooseThreaded();
  const auto start = std::chrono::steady_clock::now();
  if (!threaded) {
    for (int i = 0; i < count; ++i) wrappers_[i]->Precompute(copy);
  } else {
    // Idle workers sleep, and the blocks are split down to single batches
    // that an idle thread steals: a worker the machine is slow to run holds
    // up at most the batch it is in.
    arena_.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<int>(0, count, 1),
          [&](const tbb::blocked_range<int>& range) {
            for (int i = range.begin(); i < range.end(); ++i) wrappers_[i]->Precompute(copy);
          },
          tbb::simple_partitioner());
    });
  }
  RecordTime(threaded,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

double ParallelResidualEvaluator::RecentTimes::Typical() const {
  if (count == 0) return 0.0;
  if (count < static_cast<int>(seconds.size())) {
    return *std::min_element(seconds.begin(), seconds.begin() + count);
  }
  std::array<double, 3> sorted = seconds;
  std::sort(sorted.begin(), sorted.end());
  return sorted[1];
}

// The threads only where they pay on this machine now. An evaluator goes on
// from where the last of its kind in this process left off: the way, the
// wait between trials, the evaluations since the last trial (the first of a
// kind starts on the threads and tries the caller alone after three
// evaluations). Now and then one evaluation runs the
// other way, a trial: its time against the median of the preferred way's
// last three, just before it (the cost of an evaluation drifts as a solve
// goes on, so older times are not compared). A trial that wins switches the
// way, and the next three evaluations confirm it against the same median,
// or switch back; one that loses doubles the wait before the next trial, up
// to kMaxProbeInterval, so a machine that stays as it is pays for few.
// Which way runs changes no value.
bool ParallelResidualEvaluator::ChooseThreaded() {
  bool trial = false;
  if (confirm_left_ == 0 && ++since_probe_ >= probe_interval_) {
    since_probe_ = 0;
    trial = true;
  }
  histories[kind_].since_trial.store(since_probe_, std::memory_order_relaxed);
  return trial ? !prefer_threaded_ : prefer_threaded_;
}

bool ParallelResidualEvaluator::Faster(bool threaded, double seconds, double other_seconds) {
  return threaded ? kThreadedMargin * seconds <= other_seconds
                  : seconds < kThreadedMargin * other_seconds;
}

void ParallelResidualEvaluator::RecordTime(bool threaded, double seconds) {
  if (threaded && !workers_started.exchange(true, std::memory_order_relaxed)) return;
  RecentTimes& times = threaded ? threaded_times_ : alone_times_;
  const RecentTimes& other = threaded ? alone_times_ : threaded_times_;
  times.Add(seconds);
  if (threaded != prefer_threaded_) {  // a trial
    if (other.count > 0 && Faster(threaded, seconds, other.Typical())) {
      prefer_threaded_ = threaded;
      probe_interval_ = kProbeInterval;
      since_probe_ = 0;
      confirm_left_ = 3;
    } else {
      probe_interval_ = std::min(2 * probe_interval_, kMaxProbeInterval);
    }
  } else if (confirm_left_ > 0 && --confirm_left_ == 0 &&
             !Faster(threaded, times.Typical(), other.Typical())) {
    prefer_threaded_ = !threaded;  // the switch did not hold
    probe_interval_ = 2 * kProbeInterval;
    since_probe_ = 0;
  }
  KindHistory& history = histories[kind_];
  history.faster_way.store(prefer_threaded_ ? 1 : 2, std::memory_order_relaxed);
  history.trial_interval.store(probe_interval_, std::memory_order_relaxed);
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
