// 95 % prediction intervals of sweeps a fit did not see, the one rule of
// `identify` (validation sweeps) and `select_model` (held-out levels);
// docs/model-selection.md and docs/uncertainty.md give the beam's numbers.
//
// Predicted quantities (PredictHeldOut): each measured jump's fold nearest
// the bracket (Hz, against the bracket's centre; NaN without the fold), and
// an up-sweep's upper-branch amplitude (UpperBranchDwells: mean model
// against mean measured amplitude).
//
// The interval of q at one level (a sweep id: its up and down sweeps):
//
//   q_model +/- z sqrt(s_p^2 + s_m^2),   z = 1.95996 (normal, 0.975),
//
//   - s_p^2 = g^T C g, the parameters' uncertainty by the delta method,
//     g = dq/dp by central differences (relative step 1e-5; 1e-6 absolute
//     at 0), C the fit's prediction covariance (FitPredictionCovariance): its
//     dwells-alone covariance with each enforced jump as one observation;
//   - s_m = |q_model| x the RMS of the relative errors (q_model - q) / q of
//     the same quantity at every *other* level (0 without one).
// Inside: |q_model - q| <= half-width; a missing prediction counts outside.
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_PREDICTION_INTERVALS_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_PREDICTION_INTERVALS_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// The 0.975 quantile of the standard normal: the intervals' z.
inline constexpr double kPredictionIntervalZ = 1.959963984540054;

// The rule above in one line, for reports.
extern const char* const kPredictionIntervalRule;

// What a prediction is of.
enum class HeldOutQuantity { kJumpDown, kJumpUp, kUpperBranchAmplitude };
const char* HeldOutQuantityName(HeldOutQuantity quantity);  // "jump-down", ...
// "jump_down", "jump_up", "upper_branch_amplitude" (file keys).
const char* HeldOutQuantityKey(HeldOutQuantity quantity);

// One predicted quantity of a sweep the fit did not see, with its 95 % interval.
struct HeldOutPrediction {
  std::string sweep;  // its name, "L0.070g/up"
  HeldOutQuantity quantity = HeldOutQuantity::kJumpDown;
  double measured = 0.0;        // Hz (the bracket's centre), or the amplitude (data's unit)
  double predicted = 0.0;       // the same; NaN: no usable fit, or the model lacks the fold
  double parameter_sd = 0.0;    // s_p, the same unit; 0 when the fit has no covariance
  double model_sd = 0.0;        // s_m, the same unit
  double half_width = 0.0;      // z sqrt(s_p^2 + s_m^2); NaN without a prediction
  bool inside = false;          // measured within predicted +/- half_width
  double ErrorPercent() const;  // 100 (predicted - measured) / measured; NaN without one
};

// How often the measurements of one quantity fall inside their intervals.
struct IntervalCoverage {
  int inside = 0;
  int total = 0;                   // measured quantities (missing predictions count outside)
  double median_half_width = 0.0;  // Hz or the amplitude's unit; NaN when none
  double median_half_width_percent = 0.0;  // of the predicted value
};

struct PredictionCoverage {
  IntervalCoverage jump_down, jump_up, upper_branch;
};

// Median of `values`; NaN when empty.
double MedianOf(std::vector<double> values);

// The dwells (indices) of an up frequency sweep before its measured
// jump-down whose amplitude exceeds half the sweep's peak; else none.
std::vector<int> UpperBranchDwells(const Sweep& sweep);

// The predictions of `sweep` under `parameters` (not `usable`: NaN), with
// parameter_sd from `covariance` over the parameters `fixed` leaves free (0
// without it); the rest is left for AddPredictionIntervals. `form`: the
// response model's (model_form.h).
std::vector<HeldOutPrediction> PredictHeldOut(ModelForm form, const Sweep& sweep,
                                              const ParameterVector& parameters, bool usable,
                                              const ParameterMatrix* covariance,
                                              const std::array<bool, kNumParameters>& fixed);

// The covariance of a fit's predictions: its dwells-alone covariance C_d
// (IntervalMethod::kDataOnly) with every jump the bifurcation-range penalty
// enforces as one observation of its fold frequency f_k, standard deviation
// the bracket's half-width h_k:
//   C = (C_d^+ + sum_k g_k g_k^T / h_k^2)^+,   g_k = d f_k / d p,
// on the free parameters, computed in the scale of C_d's diagonal (^+: the
// pseudo-inverse, eigenvalues below 1e-12 of the largest dropped). Without
// the penalty, C_d. None (`why` says why) when C_d is not available.
std::optional<ParameterMatrix> FitPredictionCovariance(const std::vector<const Sweep*>& fitted,
                                                       const IdentificationOptions& options,
                                                       const ParameterVector& parameters,
                                                       std::string* why = nullptr);

// Fills model_sd, half_width and inside of every prediction; the coverage.
PredictionCoverage AddPredictionIntervals(
    const std::vector<std::vector<HeldOutPrediction>*>& levels);

// The intervals of a fit's validation sweeps (identify).
struct ValidationLevel {
  std::string level;                           // sweep id
  std::vector<HeldOutPrediction> predictions;  // of its validation sweeps, in data order
};
struct ValidationIntervals {
  std::vector<ValidationLevel> levels;  // in the order of the validation sweeps
  PredictionCoverage coverage;
  // Whether s_p came from a covariance; when not, `note` says why (s_p = 0).
  bool parameter_covariance = false;
  std::string note;
};

// Every validation sweep predicted at `parameters`, with intervals; a level
// is a validation sweep id with something to predict, its s_m from the others.
ValidationIntervals PredictValidationIntervals(const std::vector<const Sweep*>& fitted,
                                               const std::vector<const Sweep*>& validation,
                                               const IdentificationOptions& options,
                                               const ParameterVector& parameters, bool usable);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_PREDICTION_INTERVALS_H_
