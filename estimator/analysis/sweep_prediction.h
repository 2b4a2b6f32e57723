// The model's amplitude beside every measured dwell of a sweep, and how far
// the two are apart.
//
//   rms_error          = sqrt(mean_i (a_model_i - a_i)^2)        [data's unit]
//   relative_rms_error = sqrt(mean_i ((a_model_i - a_i) / a_i)^2)
//
// a_model_i is the stable root on the branch point i was measured on (the
// same root the vertical residual uses).
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_SWEEP_PREDICTION_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_SWEEP_PREDICTION_H_

#include <vector>

#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

// The model's jump for one jump of a sweep: its fold at the sweep's held
// control (a_base of a frequency sweep, Omega of an amplitude sweep).
struct PredictedJump {
  JumpKind kind = JumpKind::kJumpDown;
  bool measured = false;  // the sweep has this jump; `bracket` is its measurement
  JumpBracket bracket;
  bool exists = false;   // the model has this fold
  double control = 0.0;  // the model's jump: Omega [rad/s] or a_base
  bool inside = false;   // measured and exists: the fold lies inside the bracket
  // 100 (control - centre) / centre: the model's jump against the measured
  // bracket's centre, in % (measured and exists).
  double ErrorPercent() const { return 100.0 * (control - bracket.centre()) / bracket.centre(); }
};

// For every measured jump, the model's fold nearest the bracket; without
// one, the model's jump-up and jump-down (searched from the amplitude peak).
// `form`: the response model's (model_form.h), here and below.
std::vector<PredictedJump> PredictJumps(ModelForm form, const ParameterVector& parameters,
                                        const Sweep& sweep);

struct SweepPrediction {
  const Sweep* sweep = nullptr;
  bool fitted = false;            // false: a validation sweep, only predicted
  std::vector<StableRoot> model;  // one per point of sweep->points
  double rms_error = 0.0;
  double relative_rms_error = 0.0;
  int points_off_branch = 0;         // points whose branch ends before their control
  std::vector<PredictedJump> jumps;  // the model beside each measured jump
};

SweepPrediction PredictSweep(ModelForm form, const ParameterVector& parameters, const Sweep& sweep,
                             bool fitted);

// Sets rms_error and relative_rms_error from `model` and the sweep's points
// (after both were mapped into the measured quantity, measured_outputs.h).
void ScoreSweepPrediction(SweepPrediction* prediction);

std::vector<SweepPrediction> PredictSweeps(ModelForm form, const ParameterVector& parameters,
                                           const std::vector<const Sweep*>& fitted,
                                           const std::vector<const Sweep*>& validation);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_SWEEP_PREDICTION_H_
