// ScaledSubsetManifold: the tangent space the solver steps in, for a
// parameter block of any size.
//
// The parameters span nine decades (mu1 ~ 0.1, alpha ~ 1e9) and some are
// fixed. The block stays in physical units; the step t has one entry per
// free entry, in units of its scale s:
//   x [+] t = x + S t,   S (n x k): S(free[j], j) = s_free[j], zero elsewhere
//   y [-] x = S^+ (y - x) = ((y - x)_free[j] / s_free[j])_j
// so every step entry is a relative change of order one, and fixed entries
// never move.
#ifndef DWELLFIT_ESTIMATOR_FIT_SCALED_SUBSET_MANIFOLD_H_
#define DWELLFIT_ESTIMATOR_FIT_SCALED_SUBSET_MANIFOLD_H_

#include <vector>

#include "ceres/manifold.h"

namespace dwellfit {

class ScaledSubsetManifold : public ceres::Manifold {
 public:
  // Per entry; free scales positive, at least one entry free.
  ScaledSubsetManifold(std::vector<double> scale, const std::vector<bool>& fixed);

  int AmbientSize() const override { return static_cast<int>(scale_.size()); }
  int TangentSize() const override { return static_cast<int>(free_.size()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  std::vector<int> free_;  // ambient index of each tangent coordinate
  std::vector<double> scale_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_SCALED_SUBSET_MANIFOLD_H_
