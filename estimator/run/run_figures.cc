#include "dwellfit/estimator/run/run_figures.h"

#include <string>
#include <utility>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/curves/sweep_curves.h"
#include "glog/logging.h"

namespace dwellfit {
namespace {

FigureSweep MakeFigureSweep(const IdentificationReport& report, const ResponseCurve& curve) {
  FigureSweep figure;
  figure.id = curve.spec.name;
  figure.kind = curve.spec.kind;
  figure.held = figure.kind == SweepKind::kFrequency
                    ? StringPrintf("a_base = %.6g", curve.spec.a_base)
                    : StringPrintf("%.6g Hz", RadPerSecondToHz(curve.spec.omega_rad_s));
  figure.segments = curve.points.empty() ? 1 : curve.points.back().segment + 1;
  figure.role = "validation";
  for (const SweepPrediction& prediction : report.predictions) {
    if (prediction.sweep->id != figure.id) continue;
    if (prediction.fitted) figure.role = "fitted";
    figure.dwells += static_cast<int>(prediction.sweep->points.size());
    for (const PredictedJump& jump : prediction.jumps) {
      if (!jump.measured) continue;
      for (double control : {jump.bracket.control_before, jump.bracket.control_after}) {
        figure.jump_lines.push_back(figure.kind == SweepKind::kFrequency ? RadPerSecondToHz(control)
                                                                         : control);
      }
    }
  }
  return figure;
}

// The estimates as the figures' corner shows them: "eta_e = 100 ± 0.02",
// omega in Hz, "(fixed)" for fixed parameters.
std::vector<std::string> EstimateLines(const IdentificationReport& report) {
  std::vector<std::string> lines;
  const ParameterUncertainty& u = report.uncertainty;
  for (int i = 0; i < kNumParameters; ++i) {
    const bool omega = i == kNaturalFrequency;
    const double scale = omega ? 1.0 / kTwoPi : 1.0;
    std::string line = StringPrintf("%s = %.6g", omega ? "omega_hz" : ParameterName(i),
                                    report.result.parameters[i] * scale);
    if (report.options.fixed[i]) {
      line += " (fixed)";
    } else if (u.available) {
      line += StringPrintf(" ± %.2g", u.standard_error[i] * scale);
    }
    lines.push_back(line);
  }
  return lines;
}

}  // namespace

RunCurves TraceRunCurves(const ParameterVector& parameters,
                         const std::vector<const Sweep*>& sweeps) {
  RunCurves traced;
  try {
    traced.curves = TraceCurves(parameters, CurveSpecsForSweeps(sweeps));
  } catch (const InputError& error) {
    // The run's status says what happened; the files it can write are
    // still written.
    traced.warning = std::string("no curves or figures: ") + error.what();
    return traced;
  }
  traced.csv = CurvesToCsv(traced.curves);
  return traced;
}

void AppendCurvesAndFigures(const IdentificationReport& report, RunCurves traced,
                            std::vector<NamedFile>* files, std::ostream& out, bool render) {
  if (!traced.warning.empty()) {
    out << "warning: " << traced.warning << "\n";
    return;
  }
  FigureSet figures;
  figures.corner_lines = EstimateLines(report);
  for (const ResponseCurve& curve : traced.curves) {
    figures.sweeps.push_back(MakeFigureSweep(report, curve));
  }
  files->emplace_back("curves.csv", std::move(traced.csv));
  files->emplace_back(kFigureScriptName, GnuplotFigureScript(figures));
  if (!render) return;
  std::vector<NamedFile> inputs;
  for (const NamedFile& file : *files) {
    if (file.first == "curves.csv" || file.first == "predictions.csv" ||
        file.first == kFigureScriptName) {
      inputs.push_back(file);
    }
  }
  const RenderedFigures rendered = RenderFigures(inputs);
  if (!rendered.rendered) {
    LOG(WARNING) << rendered.warning;
    out << "warning: " << rendered.warning << "\n";
    return;
  }
  files->insert(files->end(), rendered.images.begin(), rendered.images.end());
}

}  // namespace dwellfit
