#include "estimator/sweep_prediction.h"

#include <cmath>

namespace dwellfit {

SweepPrediction PredictSweep(const ParameterVector& parameters, const Sweep& sweep, bool fitted) {
  SweepPrediction prediction;
  prediction.sweep = &sweep;
  prediction.fitted = fitted;
  double sum_squared = 0.0;
  double sum_squared_relative = 0.0;
  for (const DwellPoint& point : sweep.points) {
    const StableRoot root = ModelAmplitude(parameters, point.drive_frequency_rad_s, point.a_base,
                                           point.branch, point.amplitude);
    prediction.model.push_back(root);
    if (root.status == RootStatus::kBranchEnd) ++prediction.points_off_branch;
    const double error = root.a - point.amplitude;
    sum_squared += error * error;
    sum_squared_relative += (error / point.amplitude) * (error / point.amplitude);
  }
  const double n = static_cast<double>(sweep.points.size());
  if (n > 0) {
    prediction.rms_error = std::sqrt(sum_squared / n);
    prediction.relative_rms_error = std::sqrt(sum_squared_relative / n);
  }
  return prediction;
}

}  // namespace dwellfit
