#include "dwellfit/estimator/fit/scaled_subset_manifold.h"

#include <algorithm>
#include <utility>

#include "glog/logging.h"

namespace dwellfit {

ScaledSubsetManifold::ScaledSubsetManifold(std::vector<double> scale,
                                           const std::vector<bool>& fixed)
    : scale_(std::move(scale)) {
  CHECK_EQ(scale_.size(), fixed.size());
  for (size_t i = 0; i < scale_.size(); ++i) {
    if (fixed[i]) continue;
    CHECK_GT(scale_[i], 0.0) << "scale of entry " << i;
    free_.push_back(static_cast<int>(i));
  }
  CHECK(!free_.empty()) << "a block with no free entry must be held constant";
}

bool ScaledSubsetManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  std::copy(x, x + scale_.size(), x_plus_delta);
  for (size_t j = 0; j < free_.size(); ++j) x_plus_delta[free_[j]] += scale_[free_[j]] * delta[j];
  return true;
}

bool ScaledSubsetManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  const int k = TangentSize();
  std::fill(jacobian, jacobian + AmbientSize() * k, 0.0);
  for (int j = 0; j < k; ++j) jacobian[free_[j] * k + j] = scale_[free_[j]];
  return true;
}

bool ScaledSubsetManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  for (size_t j = 0; j < free_.size(); ++j) {
    const int i = free_[j];
    y_minus_x[j] = (y[i] - x[i]) / scale_[i];
  }
  return true;
}

bool ScaledSubsetManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  const int k = TangentSize();
  const int n = AmbientSize();
  std::fill(jacobian, jacobian + k * n, 0.0);
  for (int j = 0; j < k; ++j) jacobian[j * n + free_[j]] = 1.0 / scale_[free_[j]];
  return true;
}

}  // namespace dwellfit
