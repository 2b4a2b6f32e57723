// The curves and figures of an identify run: curves.csv (the model's whole
// response curve of every fitted and validation sweep, sweep_curves.h),
// figures.gp (figures.h) and, when gnuplot is there, its PNG and SVG images.
#ifndef DWELLFIT_ESTIMATOR_RUN_RUN_FIGURES_H_
#define DWELLFIT_ESTIMATOR_RUN_RUN_FIGURES_H_

#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/identification_report.h"
#include "dwellfit/estimator/curves/figures.h"
#include "dwellfit/estimator/curves/response_curve.h"

namespace dwellfit {

// The model's response curve of every sweep id of `sweeps` at `parameters`,
// and their curves.csv text; where the model has no curve (no damping, say),
// only a `warning` saying why.
struct RunCurves {
  std::vector<ResponseCurve> curves;
  std::string csv;
  std::string warning;
};
RunCurves TraceRunCurves(ModelForm form, const ParameterVector& parameters,
                         const std::vector<const Sweep*>& sweeps);

// Appends curves.csv and figures.gp (`curves`: TraceRunCurves of the
// report's estimate; `config`: its units and plot style) to `files` and, with
// `render`, gnuplot's images. No
// curves, or no working gnuplot, is a warning on `out`, never an error.
// Returns why no images were drawn (empty when they were).
std::string AppendCurvesAndFigures(const IdentificationReport& report, const IdentifyConfig& config,
                                   RunCurves curves, std::vector<NamedFile>* files,
                                   std::ostream& out, bool render = true);

// One measured jump against the model's: "jump_down: measured
// 194.59..194.64 Hz, model 194.61 Hz (-0.0074 Hz, -0.0038 % from the bracket
// centre, inside)"; a_base for an amplitude sweep.
std::string JumpNote(const Sweep& sweep, const PredictedJump& jump);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_RUN_FIGURES_H_
