#include "dwellfit/estimator/fit/jacobian_factor.h"

#include <cmath>

#include "Eigen/QR"
#include "ceres/cost_function.h"
#include "ceres/crs_matrix.h"
#include "glog/logging.h"

namespace dwellfit {
namespace {

// The rows of residual blocks rows[begin, end) (in the tangent coordinates
// of `blocks`) into stacked.bottomRows(), below the k rows kept for R, and
// their cost (1/2) sum r^2 into *cost. False if they cannot be evaluated or
// are not finite.
bool EvaluateChunk(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& rows,
                   size_t begin, size_t end, const std::vector<double*>& blocks, int k,
                   double* cost, Eigen::MatrixXd* stacked) {
  ceres::Problem::EvaluateOptions options;
  options.residual_blocks.assign(rows.begin() + begin, rows.begin() + end);
  options.parameter_blocks = blocks;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(options, cost, nullptr, nullptr, &crs) || !std::isfinite(*cost)) {
    return false;
  }
  CHECK_EQ(crs.num_cols, k) << "one Jacobian column per free entry";
  stacked->setZero(k + crs.num_rows, k);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int i = crs.rows[row]; i < crs.rows[row + 1]; ++i) {
      (*stacked)(k + row, crs.cols[i]) = crs.values[i];
    }
  }
  return stacked->allFinite();
}

}  // namespace

bool FactorJacobian(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& rows,
                    const std::vector<double*>& blocks, int k, int chunk_rows, double* cost,
                    Eigen::MatrixXd* r) {
  r->setZero(k, k);
  *cost = 0.0;
  Eigen::MatrixXd stacked;
  Eigen::HouseholderQR<Eigen::MatrixXd> qr;
  size_t begin = 0;
  while (begin < rows.size()) {
    size_t end = begin;
    for (int chunk = 0; end < rows.size() && chunk < chunk_rows; ++end) {
      chunk += problem->GetCostFunctionForResidualBlock(rows[end])->num_residuals();
    }
    double chunk_cost = 0.0;
    if (!EvaluateChunk(problem, rows, begin, end, blocks, k, &chunk_cost, &stacked)) return false;
    *cost += chunk_cost;
    stacked.topRows(k) = *r;
    qr.compute(stacked);
    *r = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
    begin = end;
  }
  return std::isfinite(*cost);
}

}  // namespace dwellfit
