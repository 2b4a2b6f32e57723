#include "dwellfit/estimator/analysis/sweep_prediction.h"

#include <algorithm>
#include <cmath>

#include "dwellfit/residuals/model/fold_point.h"

namespace dwellfit {
namespace {

PredictedJump PredictJump(ModelForm form, const ParameterVector& p, const Sweep& sweep,
                          JumpKind kind, double guess_control) {
  PredictedJump predicted;
  predicted.kind = kind;
  const DwellPoint& first = sweep.points.front();
  const FoldPoint fold =
      sweep.kind == SweepKind::kFrequency
          ? SolveFrequencyFold(form, p.data(), first.a_base, kind, guess_control,
                               1e-3 * guess_control)
          : SolveAmplitudeFold(form, p.data(), first.drive_frequency_rad_s, kind);
  predicted.exists = fold.exists;
  predicted.control = fold.control;
  return predicted;
}

}  // namespace

std::vector<PredictedJump> PredictJumps(ModelForm form, const ParameterVector& parameters,
                                        const Sweep& sweep) {
  std::vector<PredictedJump> predicted;
  if (sweep.points.empty()) return predicted;
  for (const JumpBracket& jump : sweep.jumps) {
    PredictedJump p = PredictJump(form, parameters, sweep, jump.kind, jump.centre());
    p.measured = true;
    p.bracket = jump;
    p.inside = p.exists && std::abs(p.control - jump.centre()) <= jump.half_width();
    predicted.push_back(p);
  }
  if (sweep.jumps.empty()) {
    const auto peak = std::max_element(
        sweep.points.begin(), sweep.points.end(),
        [](const DwellPoint& a, const DwellPoint& b) { return a.amplitude < b.amplitude; });
    for (JumpKind kind : {JumpKind::kJumpUp, JumpKind::kJumpDown}) {
      predicted.push_back(PredictJump(form, parameters, sweep, kind, peak->drive_frequency_rad_s));
    }
  }
  return predicted;
}

SweepPrediction PredictSweep(ModelForm form, const ParameterVector& parameters, const Sweep& sweep,
                             bool fitted) {
  SweepPrediction prediction;
  prediction.sweep = &sweep;
  prediction.fitted = fitted;
  for (const DwellPoint& point : sweep.points) {
    // From the measured amplitude, as the vertical error's root solve (most
    // dwells lie near their branch: no turning points to find).
    const StableRoot root = ModelAmplitudeNear(form, parameters, point.drive_frequency_rad_s,
                                               point.a_base, point.branch, point.amplitude);
    prediction.model.push_back(root);
    if (root.status == RootStatus::kBranchEnd) ++prediction.points_off_branch;
  }
  prediction.jumps = PredictJumps(form, parameters, sweep);
  ScoreSweepPrediction(&prediction);
  return prediction;
}

void ScoreSweepPrediction(SweepPrediction* prediction) {
  const std::vector<DwellPoint>& points = prediction->sweep->points;
  double sum_squared = 0.0;
  double sum_squared_relative = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double error = prediction->model[i].a - points[i].amplitude;
    sum_squared += error * error;
    sum_squared_relative += (error / points[i].amplitude) * (error / points[i].amplitude);
  }
  const double n = static_cast<double>(points.size());
  if (n > 0) {
    prediction->rms_error = std::sqrt(sum_squared / n);
    prediction->relative_rms_error = std::sqrt(sum_squared_relative / n);
  }
}

std::vector<SweepPrediction> PredictSweeps(ModelForm form, const ParameterVector& parameters,
                                           const std::vector<const Sweep*>& fitted,
                                           const std::vector<const Sweep*>& validation) {
  std::vector<SweepPrediction> predictions;
  for (const Sweep* sweep : fitted) {
    predictions.push_back(PredictSweep(form, parameters, *sweep, /*fitted=*/true));
  }
  for (const Sweep* sweep : validation) {
    predictions.push_back(PredictSweep(form, parameters, *sweep, /*fitted=*/false));
  }
  return predictions;
}

}  // namespace dwellfit
