#include "dwellfit/estimator/studies/forcing_calibration_study.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/prediction_intervals.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/studies/model_selection.h"

namespace dwellfit {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMissingPercent = 100.0;

// The errors of `sweep`'s jump-down and upper-branch amplitude at `p`.
HeldOutSweepErrors ErrorsOf(ModelForm form, const Sweep& sweep, const ParameterVector& p,
                            double scale, const std::array<bool, kNumParameters>& fixed) {
  HeldOutSweepErrors errors{sweep.Name(), scale, kNaN, kNaN};
  const bool usable = std::isfinite(scale);
  for (const HeldOutPrediction& prediction :
       PredictHeldOut(form, sweep, p, usable, nullptr, fixed)) {
    // Measured but not predicted (no fold, no usable fit): 100 %, as in method_comparison.
    const double error =
        std::isfinite(prediction.predicted) ? prediction.ErrorPercent() : kMissingPercent;
    if (prediction.quantity == HeldOutQuantity::kJumpDown) {
      errors.jump_down_percent = error;
    } else if (prediction.quantity == HeldOutQuantity::kUpperBranchAmplitude) {
      errors.upper_branch_percent = error;
    }
  }
  return errors;
}

int FreeParameters(const IdentificationOptions& options) {
  int free = 0;
  for (bool fixed : options.fixed) free += fixed ? 0 : 1;
  return free;
}

std::string Percent(double value) {
  return std::isfinite(value) ? StringPrintf("%+.3g", value) : std::string("-");
}

// The held-out table's header, its rows (without those measuring neither
// quantity when `skip_empty`) and the medians of every row given.
void HeldOutTable(const std::vector<HeldOutSweepErrors>& without,
                  const std::vector<HeldOutSweepErrors>& with, bool skip_empty,
                  std::ostringstream* out) {
  *out << "| held-out sweep | s_v | jump-down % without | with | upper branch % without | "
          "with |\n|---|---|---|---|---|---|\n";
  for (size_t v = 0; v < with.size(); ++v) {
    const HeldOutSweepErrors& a = without[v];
    const HeldOutSweepErrors& b = with[v];
    if (skip_empty && std::isnan(a.jump_down_percent) && std::isnan(a.upper_branch_percent))
      continue;
    *out << "| " << a.sweep << " | " << StringPrintf("%.4f", b.scale) << " | "
         << Percent(a.jump_down_percent) << " | " << Percent(b.jump_down_percent) << " | "
         << Percent(a.upper_branch_percent) << " | " << Percent(b.upper_branch_percent) << " |\n";
  }
  *out << StringPrintf("| **median \\|error\\|** | | %.3g | %.3g | %.3g | %.3g |\n\n",
                       MedianAbsoluteError(without, true), MedianAbsoluteError(with, true),
                       MedianAbsoluteError(without, false), MedianAbsoluteError(with, false));
}

}  // namespace

ForcingCalibrationComparison CompareForcingCalibration(
    const IdentifyConfig& config, const ForcingCalibrationOptions& calibration) {
  std::string error;
  if (!calibration.IsValid(&error)) throw InputError(error);
  const ResolvedRun run = ResolveRun(config);
  ForcingCalibrationComparison c;
  c.config = config.config_path;
  c.form = config.identification.solve.residual.form;
  c.prior_sigma = calibration.prior_sigma;
  c.held_out_dwells = calibration.held_out_dwells;
  c.parameter = calibration.parameter;
  c.without = FitRun(run).best;
  if (!c.without.IsSolutionUsable()) {
    throw InputError(config.config_path +
                     ": the fit without calibration failed: " + c.without.message);
  }
  IdentificationOptions options = run.options;
  options.initial = c.without.parameters;
  const double data_sigma = DataSigma(c.without, FreeParameters(options));
  c.with = IdentifyWithForcingCalibration(run.fitted, options, calibration, data_sigma);
  for (const Sweep* sweep : run.fitted) c.fitted.push_back(sweep->Name());
  for (const Sweep* sweep : run.validation) {
    c.errors_without.push_back(
        ErrorsOf(options.solve.residual.form, *sweep, c.without.parameters, 1.0, options.fixed));
    std::string why;
    const double scale = c.with.fit.IsSolutionUsable()
                             ? CalibrateHeldOutScale(*sweep, c.with.fit.parameters, options,
                                                     calibration, data_sigma, &why)
                             : kNaN;
    if (!std::isfinite(scale)) c.notes.push_back(why.empty() ? c.with.fit.message : why);
    ParameterVector p = c.with.fit.parameters;
    p[CalibratedIndex(calibration.parameter)] *= std::isfinite(scale) ? scale : 1.0;
    c.errors_with.push_back(ErrorsOf(options.solve.residual.form, *sweep, p, scale, options.fixed));
  }
  return c;
}

double MedianAbsoluteError(const std::vector<HeldOutSweepErrors>& errors, bool jump_down) {
  std::vector<double> values;
  for (const HeldOutSweepErrors& e : errors) {
    const double value = jump_down ? e.jump_down_percent : e.upper_branch_percent;
    if (std::isfinite(value)) values.push_back(std::abs(value));
  }
  return MedianOf(values);
}

std::string ForcingCalibrationMarkdown(const ForcingCalibrationComparison& c) {
  std::ostringstream out;
  out << "## `" << c.config << "`, " << CalibratedParameterName(c.parameter)
      << " per sweep, prior sigma " << c.prior_sigma << ", held-out scales from "
      << HeldOutDwellsName(c.held_out_dwells) << "\n\n"
      << StringPrintf(
             "Fit without calibration: %s, cost %.6g; with: %s, cost %.6g (data sigma "
             "%.4g).\n\n",
             FitStatusName(c.without.status), c.without.final_cost,
             FitStatusName(c.with.fit.status), c.with.fit.final_cost, c.with.data_sigma);
  out << "| parameter | without | with |\n|---|---|---|\n";
  for (int i = 0; i < kNumParameters; ++i) {
    out << StringPrintf("| %s | %.6g | %.6g |\n", ParameterName(c.form, i), c.without.parameters[i],
                        c.with.fit.parameters[i]);
  }
  out << "\nFitted sweeps' scales s_k:";
  for (size_t k = 0; k < c.fitted.size() && k < c.with.scales.size(); ++k) {
    out << StringPrintf(" %s %.4f%s", c.fitted[k].c_str(), c.with.scales[k],
                        k + 1 < c.fitted.size() ? "," : ".");
  }
  out << "\n\n";
  HeldOutTable(c.errors_without, c.errors_with, false, &out);
  if (c.held_out_dwells == HeldOutDwells::kBeforeJump) {
    out << "With the calibration, an up-sweep's upper-branch dwells are among those its scale is "
           "calibrated on: their amplitude is fitted there, not predicted (below_half_peak "
           "keeps it a prediction).\n\n";
  }
  for (const std::string& note : c.notes) out << "- " << note << "\n";
  return out.str();
}

std::vector<LevelOutErrors> LeaveOneLevelOut(const IdentifyConfig& config,
                                             const ForcingCalibrationOptions& calibration) {
  // The fitted and validated levels in data order, as select_model takes them.
  std::vector<std::string> levels;
  {
    const ResolvedRun run = ResolveRun(config);
    for (const std::vector<const Sweep*>* list : {&run.fitted, &run.validation}) {
      for (const Sweep* sweep : *list) {
        if (std::find(levels.begin(), levels.end(), sweep->id) == levels.end())
          levels.push_back(sweep->id);
      }
    }
    std::vector<std::string> ordered;
    for (const Sweep& sweep : run.sweeps) {
      if (std::find(levels.begin(), levels.end(), sweep.id) != levels.end() &&
          std::find(ordered.begin(), ordered.end(), sweep.id) == ordered.end())
        ordered.push_back(sweep.id);
    }
    levels = ordered;
  }
  std::vector<LevelOutErrors> folds;
  for (int out = 0; out < static_cast<int>(levels.size()); ++out) {
    IdentifyConfig fold = config;
    fold.fit_sweeps = ConfigTraining(config, levels, out);
    fold.validate_sweeps = {SweepSelection{levels[out], std::nullopt}};
    ForcingCalibrationComparison c;
    try {
      c = CompareForcingCalibration(fold, calibration);
    } catch (const InputError& e) {
      throw InputError(levels[out] + " held out: " + e.what());
    }
    folds.push_back({levels[out], c.errors_without, c.errors_with, c.notes});
  }
  return folds;
}

std::string LeaveOneLevelOutMarkdown(const IdentifyConfig& config,
                                     const ForcingCalibrationOptions& calibration,
                                     const std::vector<LevelOutErrors>& folds) {
  std::ostringstream out;
  out << "## `" << config.config_path << "`, leave one level out, "
      << CalibratedParameterName(calibration.parameter) << " per sweep, prior sigma "
      << calibration.prior_sigma << ", held-out scales from "
      << HeldOutDwellsName(calibration.held_out_dwells) << "\n\n";
  std::vector<HeldOutSweepErrors> without, with;
  for (const LevelOutErrors& fold : folds) {
    without.insert(without.end(), fold.without.begin(), fold.without.end());
    with.insert(with.end(), fold.with.begin(), fold.with.end());
  }
  HeldOutTable(without, with, true, &out);
  for (const LevelOutErrors& fold : folds) {
    for (const std::string& note : fold.notes) out << "- " << fold.level << ": " << note << "\n";
  }
  return out.str();
}

}  // namespace dwellfit
