// Inside the model-selection study (model_selection.h): the errors of a
// held-out sweep's predictions (the predictions and their intervals:
// estimator/analysis/prediction_intervals.h).
#ifndef DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_PREDICTIONS_H_
#define DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_PREDICTIONS_H_

#include <vector>

#include "dwellfit/estimator/analysis/prediction_intervals.h"
#include "dwellfit/estimator/studies/model_selection.h"

namespace dwellfit {

// The errors of `predictions` (a missing prediction counts 100 %, in Hz the
// measured frequency) with the sweep's relative RMS amplitude error when
// `relative_rms` is finite.
PredictionErrors ErrorsOf(const std::vector<HeldOutPrediction>& predictions, double relative_rms);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_PREDICTIONS_H_
