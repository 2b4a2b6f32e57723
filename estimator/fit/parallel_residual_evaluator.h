// ParallelResidualEvaluator: evaluates the residual blocks of one parameter
// block on several threads before Ceres asks for them, deterministically.
//
// Ceres runs on one thread; this class, its EvaluationCallback, evaluates
// every wrapped cost function at each new point on `num_threads` threads (the
// caller's among them; 0 means one per processor available) or, below a size,
// inline. The work is split into units fixed by the wrappers' order whatever
// the thread count, each unit writes only its own values, and Ceres sums them
// in block order, so the solve does not depend on the number of threads.
//
// Compress() stands the wrappers made so far in for one residual block of a
// few rows: with the wrappers' rows stacked as A = [J | r] (m rows), the
// Householder factorization A = Q [R_J q; 0 rho; 0 0] gives the block whose
// residuals are [q; rho] and whose Jacobian is [R_J; 0]. Its cost
// (|q|^2 + rho^2)/2 is |r|^2/2, its gradient R_J^T q is J^T r, its
// Gauss-Newton matrix R_J^T R_J is J^T J, and for every step s
// |[q; rho] + [R_J; 0] s| = |r + J s|. The factorization is a tall-skinny QR
// over chunks of about kCompressedChunkRows rows. Its Jacobian is not the
// derivative of its residuals (Q moves with the point), so only a
// Gauss-Newton-type solver may use it.
//
// A wrapper (Wrap) returns the values computed for the point the callback
// last saw, and evaluates the wrapped function itself at any other point.
//
// Use: construct with the parameter blocks the wrapped functions read, pass
// it as ceres::Problem::Options::evaluation_callback, add Wrap(cost, blocks)
// as each residual block's cost function (the problem owns the wrapper, the
// wrapper the wrapped function). A point is the values of every watched
// block, concatenated in the order given. The evaluator must outlive the
// problem's solves.
#ifndef DWELLFIT_ESTIMATOR_FIT_PARALLEL_RESIDUAL_EVALUATOR_H_
#define DWELLFIT_ESTIMATOR_FIT_PARALLEL_RESIDUAL_EVALUATOR_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "Eigen/Core"
#include "ceres/cost_function.h"
#include "ceres/evaluation_callback.h"

namespace dwellfit {

// The number of threads a `num_threads` setting means: itself when positive,
// for 0 one per processor this process may run on.
int ResolveThreadCount(int num_threads);

class ParallelResidualEvaluator : public ceres::EvaluationCallback {
 public:
  // A parameter block the solver updates (owned by the caller).
  struct Block {
    const double* values = nullptr;
    int size = 0;
  };

  // Residuals per thread at the least: an evaluation of fewer than twice
  // this many runs inline on the caller (docs/performance.md).
  static constexpr int kMinRowsPerThread = 512;

  // `blocks`: every parameter block a wrapped cost function reads, distinct.
  // `num_threads` >= 1 (ResolveThreadCount). `min_rows_per_thread` >= 1:
  // kMinRowsPerThread but where a benchmark measures the threads on less.
  ParallelResidualEvaluator(std::vector<Block> blocks, int num_threads,
                            int min_rows_per_thread = kMinRowsPerThread);
  // One block of `size` doubles that every wrapped cost function reads.
  ParallelResidualEvaluator(const double* parameters, int size, int num_threads,
                            int min_rows_per_thread = kMinRowsPerThread);
  ~ParallelResidualEvaluator() override;

  // Takes ownership of `cost_function`, whose parameter blocks are
  // `parameter_blocks` (each a watched block, in the residual block's
  // order); returns its replaying wrapper, owned by the caller.
  ceres::CostFunction* Wrap(ceres::CostFunction* cost_function,
                            const std::vector<double*>& parameter_blocks);
  // The same for a cost function of the first watched block alone.
  ceres::CostFunction* Wrap(ceres::CostFunction* cost_function);
  // The one residual block that stands in for every wrapper made so far
  // (see above; at most once): `size + 1` residuals on every watched block,
  // in order. Owned by the caller. The wrappers stay owned as before, and
  // stay usable, in a problem of their own, for their values at the point.
  ceres::CostFunction* Compress();

  // Makes room for `wrappers` more wrappers of one parameter block each,
  // holding `residuals` residuals over the whole point between them (the
  // dwells, in batches), so that wrapping them copies no stored values. Only
  // capacity: wrappers of any shape may follow.
  void Reserve(int wrappers, int residuals);

  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;
  // The next evaluation evaluates every wrapper anew, even at the point the
  // wrappers hold values for.
  void Invalidate() { computed_ = false; }

  // Where the solver's current iterate holds the entry the caller keeps at
  // `value` (an entry of a watched block; nullptr for any other pointer):
  // the point of the last evaluation with Jacobians, which Ceres' trust-region
  // minimizer makes at every accepted step. With non-monotonic steps Ceres
  // writes only the best point so far into the caller's blocks, so during an
  // excursion above that cost they lag behind the iterate.
  const double* IterateEntry(const double* value) const;

  // The gradient of (1/2) sum |r|^2 over every wrapped block at `point` (a
  // point as above), in the blocks' own coordinates (no manifold, no
  // bounds), evaluated on the threads and summed in block order. False if a
  // block fails to evaluate.
  bool CostGradient(const double* point, std::vector<double>* gradient);

  // Wrapper evaluations answered from the precomputed values, and those that
  // had to evaluate the wrapped function themselves (a point the callback
  // did not see, or a wrapper added after it ran).
  std::int64_t replayed() const { return replayed_; }
  std::int64_t evaluated_directly() const { return evaluated_directly_; }

 private:
  class ReplayingCostFunction;
  class CompressedCostFunction;
  class Workers;

  // Rows of the compressed wrappers' chunks, at the least (the last may
  // have fewer).
  static constexpr int kCompressedChunkRows = 256;

  // Evaluates every wrapper at last_point_, on the threads, and factors the
  // compressed ones.
  void PrecomputeAll();
  // Work unit `unit` of PrecomputeAll at `point`: a chunk of compressed
  // wrappers, evaluated and factored, or one other wrapper.
  void PrecomputeUnit(int unit, const double* point);
  // The R of chunk `chunk` (its wrappers evaluated) into chunk_r_.
  void FactorChunk(int chunk);
  // The chunks' R, stacked, into compressed_r_.
  void CombineChunks();
  // CompressedCostFunction::Evaluate.
  bool EvaluateCompressed(double const* const* parameters, double* residuals, double** jacobians);
  // Whether the watched blocks' values, block b's at values(b) (the blocks'
  // own, BlockValues, or a cost function's parameters), are last_point_.
  template <typename Values>
  bool AtLastPoint(const Values& values) const;
  // Those values, concatenated, into `point` (resized to a point).
  template <typename Values>
  void CopyToPoint(const Values& values, std::vector<double>* point) const;
  // The watched blocks' own values, for the two above.
  auto BlockValues() const {
    return [this](size_t b) -> const double* { return blocks_[b].values; };
  }

  const std::vector<Block> blocks_;
  std::vector<int> offsets_;  // of each block in a point
  int size_ = 0;              // of a point
  const int num_threads_;
  const int min_rows_per_thread_;
  // num_threads_ - 1 threads beside the caller's, started with the first
  // evaluation that runs threaded.
  std::unique_ptr<Workers> workers_;
  std::vector<ReplayingCostFunction*> wrappers_;  // owned by the problem
  int rows_ = 0;                                  // residuals over the wrappers
  // Every wrapper's values at last_point_, contiguous per wrapper, in order
  // (ReplayingCostFunction says what), and where each wrapper's parameter
  // blocks start in a point: one array each rather than two allocations per
  // wrapper (a million dwells hold a million wrappers).
  std::vector<double> storage_;
  std::vector<int> block_offsets_;
  bool computed_ = false;           // last_point_ holds a point evaluated
  std::vector<double> last_point_;  // the point the wrappers hold values for
  std::vector<double> iterate_;     // the last point evaluated with Jacobians
  std::int64_t replayed_ = 0;
  std::int64_t evaluated_directly_ = 0;
  // Compress(): wrappers [0, compressed_) stand behind one block, in chunks
  // ending at chunk_ends_; per chunk its (size_ + 1)^2 R, row-major, and
  // whether its wrappers evaluated; their R combined at last_point_.
  int compressed_ = 0;
  std::vector<int> chunk_ends_;
  std::vector<double> chunk_r_;
  std::vector<char> chunk_ok_;
  Eigen::MatrixXd compressed_r_;
  bool compressed_ok_ = false;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_PARALLEL_RESIDUAL_EVALUATOR_H_
