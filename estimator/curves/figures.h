// Chapter-style figures (the chapter's Figures 3.4-3.14) drawn by gnuplot
// from the files identify writes: per sweep id, the measured up and down
// dwells with distinct markers over the model's curve (stable branches
// solid, unstable dashed, folds marked, the backbone dotted), the measured
// jump brackets as vertical lines, the estimates in a corner, and below it
// the residual a - a_model of every dwell.
//
// The script (figures.gp) reads curves.csv and predictions.csv from its own
// folder and writes <stem>.png, or <stem>.svg with `gnuplot -e "fmt='svg'"
// figures.gp`; a user can restyle it and run it again.
#ifndef DWELLFIT_ESTIMATOR_CURVES_FIGURES_H_
#define DWELLFIT_ESTIMATOR_CURVES_FIGURES_H_

#include <string>
#include <utility>
#include <vector>

#include "dwellfit/residuals/model/sweep_vocabulary.h"

namespace dwellfit {

inline constexpr char kFigureScriptName[] = "figures.gp";

struct FigureSweep {
  std::string id;  // sweep id, as in curves.csv and predictions.csv
  SweepKind kind = SweepKind::kFrequency;
  std::string role;                // "fitted" or "validation"
  std::string held;                // the held control in words: "a_base = 0.01", "41.5 Hz"
  int segments = 1;                // response segments of the sweep in curves.csv
  int dwells = 0;                  // measured dwells (up and down): sets the marker size
  std::vector<double> jump_lines;  // measured jump bracket edges [Hz or a_base]
};

struct FigureSet {
  std::vector<FigureSweep> sweeps;
  std::vector<std::string> corner_lines;  // the estimates, one per line
  std::string amplitude_unit = "data's unit";
};

// "figure_<role>_<id>" with characters outside [A-Za-z0-9._-] replaced by '_'.
std::string FigureFileStem(const FigureSweep& sweep);

// The gnuplot script for `figures`.
std::string GnuplotFigureScript(const FigureSet& figures);

// A file to write: name and content.
using NamedFile = std::pair<std::string, std::string>;

struct RenderedFigures {
  bool rendered = false;
  std::string warning;            // why not (no gnuplot on PATH, gnuplot failed)
  std::vector<NamedFile> images;  // <stem>.png and <stem>.svg, by name
};

// Writes `inputs` (the CSVs and the script named kFigureScriptName) into a
// fresh temporary folder, runs gnuplot there for PNG and for SVG, and returns
// the images it made; the folder is removed. Never throws for a missing or
// failing gnuplot: the result then says why in `warning`.
RenderedFigures RenderFigures(const std::vector<NamedFile>& inputs);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_CURVES_FIGURES_H_
