#include "dwellfit/estimator/studies/model_selection_predictions.h"

#include <cmath>

namespace dwellfit {

PredictionErrors ErrorsOf(const std::vector<HeldOutPrediction>& predictions, double relative_rms) {
  PredictionErrors errors;
  for (const HeldOutPrediction& p : predictions) {
    const bool known = std::isfinite(p.predicted);
    const double percent = known ? std::abs(p.ErrorPercent()) : 100.0;
    const double hz = known ? std::abs(p.predicted - p.measured) : p.measured;
    switch (p.quantity) {
      case HeldOutQuantity::kJumpDown:
        errors.jump_down_percent.push_back(percent);
        errors.jump_down_hz.push_back(hz);
        break;
      case HeldOutQuantity::kJumpUp:
        errors.jump_up_percent.push_back(percent);
        errors.jump_up_hz.push_back(hz);
        break;
      case HeldOutQuantity::kUpperBranchAmplitude:
        errors.upper_branch_percent.push_back(percent);
        break;
    }
  }
  if (std::isfinite(relative_rms)) errors.relative_rms.push_back(relative_rms);
  return errors;
}

void AddPredictionIntervals(VariantResult* result) {
  std::vector<std::vector<HeldOutPrediction>*> levels;
  for (CrossValidationFold& fold : result->folds) levels.push_back(&fold.predictions);
  const PredictionCoverage coverage = AddPredictionIntervals(levels);
  result->jump_down_coverage = coverage.jump_down;
  result->jump_up_coverage = coverage.jump_up;
  result->upper_branch_coverage = coverage.upper_branch;
}

}  // namespace dwellfit
