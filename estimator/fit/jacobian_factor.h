// The R factor of a problem's Jacobian, one chunk of residual blocks at a
// time, so that an N x k Jacobian is never held whole (N in the millions).
//
// J (the residual blocks `rows` in the tangent coordinates of `blocks`) = Q R:
// each chunk J_c of about `chunk_rows` rows is folded in by a Householder QR
// of [R; J_c], whose R' has R'^T R' = R^T R + J_c^T J_c. So R^T R = J^T J at
// the end, without forming J^T J (which would square the condition number).
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
