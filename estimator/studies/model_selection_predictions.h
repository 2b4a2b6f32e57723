// Inside the model-selection study (model_selection.h): the held-out
// predictions of one sweep, their errors, and their parameter uncertainty
// by the delta method.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_PREDICTIONS_H_
#define DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_PREDICTIONS_H_

#include <array>
#include <vector>

#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/studies/model_selection.h"

namespace dwellfit {

// The dwells of the upper branch of an up frequency sweep with a measured
// jump-down: those before the jump whose amplitude exceeds half the sweep's
// peak (indices into sweep.points). Empty for any other sweep.
std::vector<int> UpperBranchDwells(const Sweep& sweep);

// The predictions of `sweep`'s measured jumps (frequency sweeps only) and of
// its upper-branch amplitude, under `parameters` (none usable: every
// prediction NaN). With `covariance` (physical units, zero rows for fixed
// parameters), each prediction's parameter_sd by the delta method over the
// parameters `fixed` leaves free; without it, 0. model_sd, half_width and
// inside are left for AddPredictionIntervals.
std::vector<HeldOutPrediction> PredictHeldOut(const Sweep& sweep, const ParameterVector& parameters,
                                              bool usable, const ParameterMatrix* covariance,
                                              const std::array<bool, kNumParameters>& fixed);

// The covariance a fold's predictions are uncertain by: the fit's
// dwells-alone covariance C_d (EstimateUncertainty, kDataOnly) with every
// enforced jump of the fitted frequency sweeps (the bifurcation-range
// penalty's, when on) taken as one observation of its fold frequency f_k
// with the bracket's half-width h_k as standard deviation -- what the
// penalty holds it to:
//   C = (C_d^+ + sum_k g_k g_k^T / h_k^2)^+,   g_k = d f_k / d p,
// on the free parameters, computed in the scale of C_d's diagonal (^+: the
// pseudo-inverse, eigenvalues below 1e-12 of the largest dropped). Without
// the penalty, C_d.
ParameterMatrix PredictionCovariance(const ParameterMatrix& data_only,
                                     const std::vector<const Sweep*>& fitted,
                                     const IdentificationOptions& options,
                                     const ParameterVector& parameters);

// The errors of `predictions` (a missing prediction counts 100 %, in Hz the
// measured frequency) with the sweep's relative RMS amplitude error when
// `relative_rms` is finite.
PredictionErrors ErrorsOf(const std::vector<HeldOutPrediction>& predictions, double relative_rms);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_PREDICTIONS_H_
