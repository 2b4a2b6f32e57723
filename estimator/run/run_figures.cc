#include "dwellfit/estimator/run/run_figures.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/curves/sweep_curves.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "glog/logging.h"

namespace dwellfit {
namespace {

std::string HeldControl(const CurveSpec& spec, const std::string& base_unit) {
  return spec.kind == SweepKind::kFrequency
             ? StringPrintf("a_base = %.6g%s", spec.a_base,
                            base_unit.empty() ? "" : (" " + base_unit).c_str())
             : StringPrintf("%.6g Hz", RadPerSecondToHz(spec.omega_rad_s));
}

// The swept control as the figures show it: Hz, or a_base.
double FigureX(SweepKind kind, double omega_rad_s, double a_base) {
  return kind == SweepKind::kFrequency ? RadPerSecondToHz(omega_rad_s) : a_base;
}

// The model's branches: a line for each run of one stability, joined at the
// fold where one run ends and the next starts.
void AddCurveLines(const ResponseCurve& curve, FigureSweep* figure) {
  const CurvePoint* previous = nullptr;
  for (const CurvePoint& p : curve.points) {
    const FigurePoint point{FigureX(curve.spec.kind, p.omega_rad_s, p.a_base), p.a};
    std::vector<FigureLine>& lines = p.stable ? figure->stable : figure->unstable;
    const bool joined = previous != nullptr && p.continues;
    if (!joined || previous->segment != p.segment) {
      if (joined) (previous->stable ? figure->stable : figure->unstable).back().push_back(point);
      lines.emplace_back();
    }
    lines.back().push_back(point);
    if (p.fold) figure->folds.push_back(point);
    previous = &p;
  }
  for (const BackbonePoint& p : curve.backbone) {
    figure->backbone.push_back({FigureX(curve.spec.kind, p.omega_rad_s, p.a_base), p.a});
  }
}

// The measured dwells and their residuals in the fit's error measure.
void AddDwells(const SweepPrediction& prediction, const ResidualOptions& measure,
               FigureSweep* figure) {
  const Sweep& sweep = *prediction.sweep;
  const bool up = sweep.direction == SweepDirection::kUp;
  for (size_t i = 0; i < sweep.points.size(); ++i) {
    const DwellPoint& point = sweep.points[i];
    const double x = FigureX(sweep.kind, point.drive_frequency_rad_s, point.a_base);
    const double a = point.amplitude;
    const double model = prediction.model[i].a;
    double residual = std::numeric_limits<double>::quiet_NaN();  // none without a model amplitude
    AmplitudeError(MeasuredTerm(a, measure.error, measure.amplitude_floor), model, measure.error,
                   1.0, measure.amplitude_floor, &residual);
    (up ? figure->up : figure->down).push_back({x, a});
    (up ? figure->up_residual : figure->down_residual).push_back({x, residual});
  }
}

FigureSweep MakeFigureSweep(const IdentificationReport& report, const ResponseCurve& curve,
                            const std::string& base_unit) {
  FigureSweep figure;
  figure.id = curve.spec.name;
  figure.kind = curve.spec.kind;
  figure.held = HeldControl(curve.spec, base_unit);
  figure.role = "validation";
  AddCurveLines(curve, &figure);
  for (const SweepPrediction& prediction : report.predictions) {
    if (prediction.sweep->id != figure.id) continue;
    if (prediction.fitted) figure.role = "fitted";
    AddDwells(prediction, report.options.solve.residual, &figure);
    for (const PredictedJump& jump : prediction.jumps) {
      if (!jump.measured) continue;
      figure.notes.push_back(prediction.sweep->Name() + " " + JumpNote(*prediction.sweep, jump));
      for (double control : {jump.bracket.control_before, jump.bracket.control_after}) {
        figure.jump_lines.push_back(FigureX(figure.kind, control, control));
      }
    }
  }
  return figure;
}

// The prediction interval of `sweep`'s jump of `kind` (frequency sweeps of
// validation levels), or NaN.
std::pair<double, double> JumpBand(const ValidationIntervals& intervals, const Sweep& sweep,
                                   JumpKind kind) {
  const HeldOutQuantity quantity =
      kind == JumpKind::kJumpDown ? HeldOutQuantity::kJumpDown : HeldOutQuantity::kJumpUp;
  for (const ValidationLevel& level : intervals.levels) {
    for (const HeldOutPrediction& held : level.predictions) {
      if (held.sweep == sweep.Name() && held.quantity == quantity &&
          std::isfinite(held.half_width)) {
        return {held.predicted - held.half_width, held.predicted + held.half_width};
      }
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan};
}

// Every measured jump with the model's fold beside it, for the overview.
std::vector<OverviewJump> OverviewJumps(const IdentificationReport& report) {
  std::vector<OverviewJump> overview;
  for (const SweepPrediction& prediction : report.predictions) {
    const Sweep& sweep = *prediction.sweep;
    if (sweep.points.empty()) continue;
    const DwellPoint& first = sweep.points.front();
    for (const PredictedJump& jump : prediction.jumps) {
      if (!jump.measured) continue;
      OverviewJump row;
      row.sweep_kind = sweep.kind;
      row.kind = jump.kind;
      row.held = sweep.kind == SweepKind::kFrequency
                     ? first.a_base
                     : RadPerSecondToHz(first.drive_frequency_rad_s);
      const double before =
          FigureX(sweep.kind, jump.bracket.control_before, jump.bracket.control_before);
      const double after =
          FigureX(sweep.kind, jump.bracket.control_after, jump.bracket.control_after);
      row.measured_low = std::min(before, after);
      row.measured_high = std::max(before, after);
      row.model = jump.exists ? FigureX(sweep.kind, jump.control, jump.control)
                              : std::numeric_limits<double>::quiet_NaN();
      std::tie(row.band_low, row.band_high) =
          JumpBand(report.validation_intervals, sweep, jump.kind);
      overview.push_back(row);
    }
  }
  return overview;
}

// The figures' corner: the estimates with their 95 % intervals (omega in Hz),
// fixed parameters and those held at a bound marked, and the run's status.
std::vector<std::string> EstimateLines(const IdentificationReport& report) {
  const ParameterUncertainty& u = report.uncertainty;
  std::vector<std::string> lines = {u.available
                                        ? "estimate [95 % interval, " + u.interval_kind + "]"
                                        : "estimate (no interval: " + u.message + ")"};
  std::vector<int> held;
  if (!report.result.stages.empty()) held = report.result.stages.back().held_at_bound;
  for (int i = 0; i < kNumParameters; ++i) {
    const bool omega = i == kNaturalFrequency;
    const double scale = omega ? 1.0 / kTwoPi : 1.0;
    std::string line = StringPrintf(
        "%s = %.6g", omega ? "omega_hz" : ParameterName(report.options.solve.residual.form, i),
        report.result.parameters[i] * scale);
    if (report.options.fixed[i]) {
      line += " (fixed)";
    } else if (std::find(held.begin(), held.end(), i) != held.end()) {
      line += " (held at its bound)";
    } else if (u.available) {
      line += StringPrintf(" [%.4g, %.4g]", u.ci95_low[i] * scale, u.ci95_high[i] * scale);
    }
    lines.push_back(line);
  }
  lines.push_back(StringPrintf("status: %s, cost %.6g", FitStatusName(report.result.status),
                               report.result.final_cost));
  return lines;
}

// The y label of the residual panel: the fit's own error measure.
std::string ResidualLabel(const ResidualOptions& measure, const std::string& unit) {
  if (measure.error == ErrorMeasure::kAbsolute) return "a - a_model [" + unit + "]";
  if (measure.amplitude_floor == 0.0) return "ln a - ln a_model";
  return StringPrintf("ln(a + f) - ln(a_model + f), f = %.3g", measure.amplitude_floor);
}

}  // namespace

// "jump_down: measured 194.2..194.6 Hz, model 196.1 Hz (+1.7 Hz, +0.88 % from the bracket's
// centre)".
std::string JumpNote(const Sweep& sweep, const PredictedJump& jump) {
  const bool hz = sweep.kind == SweepKind::kFrequency;
  auto shown = [&](double control) { return hz ? RadPerSecondToHz(control) : control; };
  const char* unit = hz ? " Hz" : "";
  std::string note =
      StringPrintf("%s: measured %.5g..%.5g%s, model ", JumpKindName(jump.kind),
                   shown(jump.bracket.control_before), shown(jump.bracket.control_after), unit);
  if (!jump.exists) return note + "has no fold";
  const double centre = shown(jump.bracket.centre());
  const double error = shown(jump.control) - centre;
  return note + StringPrintf("%.5g%s (%+.3g%s, %+.3g %% from the bracket centre%s)",
                             shown(jump.control), unit, error, unit, jump.ErrorPercent(),
                             jump.inside ? ", inside" : "");
}

RunCurves TraceRunCurves(ModelForm form, const ParameterVector& parameters,
                         const std::vector<const Sweep*>& sweeps) {
  RunCurves traced;
  try {
    traced.curves = TraceCurves(form, parameters, CurveSpecsForSweeps(sweeps));
  } catch (const InputError& error) {
    // The run's status says what happened; the files it can write are
    // still written.
    traced.warning = std::string("no curves or figures: ") + error.what();
    return traced;
  }
  traced.csv = CurvesToCsv(traced.curves);
  return traced;
}

std::string AppendCurvesAndFigures(const IdentificationReport& report, const IdentifyConfig& config,
                                   RunCurves traced, std::vector<NamedFile>* files,
                                   std::ostream& out, bool render) {
  if (!traced.warning.empty()) {
    out << "warning: " << traced.warning << "\n";
    return traced.warning;
  }
  FigureSet figures;
  figures.corner_lines = EstimateLines(report);
  figures.overview = OverviewJumps(report);
  for (const ModalPoint& p : report.modal.points) {
    figures.modal.push_back(
        {p.a, p.omega_hz, p.omega_hz_low, p.omega_hz_high, p.zeta, p.zeta_low, p.zeta_high});
  }
  figures.amplitude_unit = config.units.a.empty() ? "data's unit" : config.units.a;
  figures.control_unit = config.units.a_base.empty() ? "data's unit" : config.units.a_base;
  // The test as run names the quantities; the defaults keep "a" and "base level a_base".
  const char* amplitude[] = {"a", "velocity amplitude", "acceleration amplitude"};
  figures.amplitude_name = amplitude[config.test.ResponsePower()];
  figures.level_name = config.test.excitation == Excitation::kForce ? "force level"
                       : config.test.excitation == Excitation::kBaseDisplacement
                           ? "base displacement level"
                           : "base level a_base";
  if (config.test.ResponsePower() != 0) {
    figures.displacement_unit = ModelFormUnits(config.units, config.test).a;
  }
  figures.log_amplitude = config.log_amplitude;
  figures.residual_label = ResidualLabel(report.options.solve.residual, figures.amplitude_unit);
  for (const ResponseCurve& curve : traced.curves)
    figures.sweeps.push_back(MakeFigureSweep(report, curve, config.units.a_base));
  files->emplace_back("curves.csv", std::move(traced.csv));
  files->emplace_back(kFigureScriptName, GnuplotFigureScript(figures));
  if (!render) return "the run was asked for none (--figures=false)";
  const RenderedFigures rendered = RenderFigures({files->back()});
  if (!rendered.rendered) {
    LOG(WARNING) << rendered.warning;
    out << "warning: " << rendered.warning << "\n";
    return rendered.warning;
  }
  files->insert(files->end(), rendered.images.begin(), rendered.images.end());
  return "";
}

}  // namespace dwellfit
