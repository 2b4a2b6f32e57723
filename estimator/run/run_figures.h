// The curves and figures of an identify run: curves.csv (the model's whole
// response curve of every fitted and validation sweep, sweep_curves.h),
// figures.gp (figures.h) and, when gnuplot is there, its PNG and SVG images.
#ifndef DWELLFIT_ESTIMATOR_RUN_RUN_FIGURES_H_
#define DWELLFIT_ESTIMATOR_RUN_RUN_FIGURES_H_

#include <ostream>
#include <string>
#include <vector>

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
RunCurves TraceRunCurves(const ParameterVector& parameters,
                         const std::vector<const Sweep*>& sweeps);

// Appends curves.csv and figures.gp (`curves`: TraceRunCurves of the
// report's estimate) to `files`, which must hold predictions.csv, and with
// `render` gnuplot's images. No curves, or no working gnuplot, is a warning
// on `out`, never an error.
void AppendCurvesAndFigures(const IdentificationReport& report, RunCurves curves,
                            std::vector<NamedFile>* files, std::ostream& out, bool render = true);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_RUN_FIGURES_H_
