// The R factor of a problem's Jacobian, one chunk of residual blocks at a
// time, so that an N x k Jacobian is never held whole (N in the millions).
//
// With J the Jacobian of the residual blocks `rows` in the tangent
// coordinates of `blocks` (one column per free entry, in order), J = Q R:
// each chunk J_c of about `chunk_rows` rows (whole residual blocks) is folded
// in by a Householder QR of [R; J_c], whose R' has R'^T R' = R^T R + J_c^T J_c.
// So after the last chunk R^T R = J^T J, without forming J^T J (which would
// square the condition number). R has J's column norms, singular values and
// right singular vectors.
//
// Used by the covariance (estimator/analysis/block_covariance.h) and by the
// valley polish of a creeping solve (valley_polish.h).
#ifndef DWELLFIT_ESTIMATOR_FIT_JACOBIAN_FACTOR_H_
#define DWELLFIT_ESTIMATOR_FIT_JACOBIAN_FACTOR_H_

#include <vector>

#include "Eigen/Core"
#include "ceres/problem.h"

namespace dwellfit {

// F = (1/2) sum r^2 over `rows` into *cost and the upper-triangular k x k
// factor R into *r, at the blocks' current values. False if some residual
// block cannot be evaluated or is not finite.
bool FactorJacobian(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& rows,
                    const std::vector<double*>& blocks, int k, int chunk_rows, double* cost,
                    Eigen::MatrixXd* r);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_JACOBIAN_FACTOR_H_
