// ParallelResidualEvaluator: evaluates the residual blocks of a problem on
// several threads before Ceres asks for them, deterministically.
//
// As the problem's EvaluationCallback it evaluates every wrapped cost
// function at each new point on `num_threads` threads (the caller's among
// them) or, below a size, inline. The work units are fixed by the wrappers'
// order whatever the thread count, each writes only its own values, and
// Ceres sums them in block order: the solve does not depend on the thread
// count. A wrapper (Wrap) replays the values computed for the point the
// callback last saw, and evaluates its function itself at any other point.
//
// Compress() stands the wrappers in for one residual block of a few rows:
// with their rows stacked as A = [J | r], the Householder factorization
// A = Q [R_J q; 0 rho; 0 0] gives the block with residuals [q; rho] and
// Jacobian [R_J; 0]: the same cost |r|^2/2, gradient J^T r, Gauss-Newton
// matrix J^T J, and |[q; rho] + [R_J; 0] s| = |r + J s| for every step s.
// It is a tall-skinny QR over chunks of about kCompressedChunkRows rows. Its
// Jacobian is not the derivative of its residuals (Q moves with the point),
// so only a Gauss-Newton-type solver may use it.
//
// Use: construct with the parameter blocks the wrapped functions read, pass
// it as ceres::Problem::Options::evaluation_callback, and add Wrap(cost,
// blocks) as each residual block's cost function. A point is the values of
// every watched block, concatenated in order. The evaluator must outlive
// the problem's solves.
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

  // Residuals per thread at the least: fewer than twice this many are
  // evaluated inline (docs/performance.md).
  static constexpr int kMinRowsPerThread = 512;

  // `blocks`: every parameter block a wrapped cost function reads, distinct.
  // `num_threads` >= 1; `min_rows_per_thread` >= 1 (less for benchmarks).
  ParallelResidualEvaluator(std::vector<Block> blocks, int num_threads,
                            int min_rows_per_thread = kMinRowsPerThread);
  ~ParallelResidualEvaluator() override;

  // Takes ownership of `cost_function` on `parameter_blocks` (watched
  // blocks); returns its replaying wrapper, owned by the caller.
  ceres::CostFunction* Wrap(ceres::CostFunction* cost_function,
                            const std::vector<double*>& parameter_blocks);
  // The one residual block that stands in for every wrapper made so far
  // (above; at most once): `size + 1` residuals on every watched block.
  // Owned by the caller; the wrappers stay usable in a problem of their own.
  ceres::CostFunction* Compress();

  // Makes room for `wrappers` more wrappers of one parameter block each with
  // `residuals` residuals between them (capacity only).
  void Reserve(int wrappers, int residuals);

  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;
  // The next evaluation evaluates every wrapper anew, even at the same point.
  void Invalidate() { computed_ = false; }

  // Where the solver's current iterate (the point of the last evaluation
  // with Jacobians) holds the entry the caller keeps at `value` (nullptr
  // outside the watched blocks). With non-monotonic steps Ceres writes only
  // the best point so far into the caller's blocks, which then lag behind.
  const double* IterateEntry(const double* value) const;

  // The gradient of (1/2) sum |r|^2 over every wrapper at `point`, in the
  // blocks' own coordinates, summed in block order. False if a block fails.
  bool CostGradient(const double* point, std::vector<double>* gradient);

  // Wrapper evaluations replayed, and those evaluated directly.
  std::int64_t replayed() const { return replayed_; }
  std::int64_t evaluated_directly() const { return evaluated_directly_; }

 private:
  class ReplayingCostFunction;
  class CompressedCostFunction;
  class Workers;

  // Rows of a compressed chunk, at the least (the last may have fewer).
  static constexpr int kCompressedChunkRows = 256;

  // Evaluates every wrapper at last_point_ and factors the compressed ones.
  void PrecomputeAll();
  // A unit of PrecomputeAll: a chunk of compressed wrappers, or one other.
  void PrecomputeUnit(int unit, const double* point);
  void FactorChunk(int chunk);  // its R into chunk_r_
  void CombineChunks();         // the chunks' R, stacked, into compressed_r_
  bool EvaluateCompressed(double const* const* parameters, double* residuals, double** jacobians);
  // Whether block b's values at values(b), for every b, are last_point_.
  template <typename Values>
  bool AtLastPoint(const Values& values) const;
  // Those values, concatenated, into `point`.
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
  // num_threads_ - 1 threads beside the caller's, started when first needed.
  std::unique_ptr<Workers> workers_;
  std::vector<ReplayingCostFunction*> wrappers_;  // owned by the problem
  int rows_ = 0;                                  // residuals over the wrappers
  // Every wrapper's values at last_point_ and where its parameter blocks
  // start in a point (ReplayingCostFunction): one array each rather than two
  // allocations per wrapper (a million dwells hold a million wrappers).
  std::vector<double> storage_;
  std::vector<int> block_offsets_;
  bool computed_ = false;           // last_point_ holds a point evaluated
  std::vector<double> last_point_;  // the point the wrappers hold values for
  std::vector<double> iterate_;     // the last point evaluated with Jacobians
  std::int64_t replayed_ = 0;
  std::int64_t evaluated_directly_ = 0;
  // Compress(): wrappers [0, compressed_) in chunks ending at chunk_ends_;
  // per chunk its (size_ + 1)^2 R, row-major, and whether it evaluated.
  int compressed_ = 0;
  std::vector<int> chunk_ends_;
  std::vector<double> chunk_r_;
  std::vector<char> chunk_ok_;
  Eigen::MatrixXd compressed_r_;
  bool compressed_ok_ = false;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_PARALLEL_RESIDUAL_EVALUATOR_H_
