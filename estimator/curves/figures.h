// Chapter-style figures (the chapter's Figures 3.4-3.14) drawn by gnuplot:
// per sweep id, the measured up and down dwells with distinct markers over
// the model's curve (stable branches solid, unstable dashed, folds marked,
// the backbone dotted), the measured jump brackets as labelled vertical
// lines, the estimates and the run's status in a corner, the model's jumps
// against the measured ones under the title, and below it the residual of
// every dwell in the fit's own error measure.
//
// The script (figures.gp) carries its data as gnuplot datablocks, one set a
// sweep, so that each plot reads only its own points; `gnuplot figures.gp`
// writes <stem>.png, `gnuplot -e "fmt='svg'" figures.gp` <stem>.svg, and a
// user can restyle it and run it again with nothing beside it.
#ifndef DWELLFIT_ESTIMATOR_CURVES_FIGURES_H_
#define DWELLFIT_ESTIMATOR_CURVES_FIGURES_H_

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "dwellfit/residuals/model/sweep_vocabulary.h"

namespace dwellfit {

inline constexpr char kFigureScriptName[] = "figures.gp";

// A point of a figure: x is the swept control (Hz, or a_base in the data's
// unit), y the amplitude or the residual.
struct FigurePoint {
  double x = 0.0;
  double y = 0.0;
};
using FigureLine = std::vector<FigurePoint>;

struct FigureSweep {
  std::string id;  // sweep id, as in curves.csv and predictions.csv
  SweepKind kind = SweepKind::kFrequency;
  std::string role;                // "fitted" or "validation"
  std::string held;                // the held control in words: "a_base = 0.01 g", "41.5 Hz"
  std::vector<std::string> notes;  // under the title: the model's jumps against the measured
  std::vector<FigureLine> stable, unstable;  // the model's branches, one line per run
  FigureLine backbone, folds;
  FigureLine up, down;                    // measured dwells
  FigureLine up_residual, down_residual;  // their residuals (NaN where the model has none)
  std::vector<double> jump_lines;         // measured jump bracket edges [Hz or a_base]
};

// One measured jump for the overview figure: where the sweeps jump against
// their held control (the jump frequency against the base level for
// frequency sweeps, the jump level against the drive frequency for amplitude
// sweeps). Swept and held values in Hz or a_base; NaN where one is missing.
struct OverviewJump {
  SweepKind sweep_kind = SweepKind::kFrequency;
  double held = 0.0;  // the sweep's a_base, or its drive frequency [Hz]
  JumpKind kind = JumpKind::kJumpDown;
  double measured_low = 0.0, measured_high = 0.0;  // the measured bracket
  double model = 0.0;                              // the model's fold
  double band_low = 0.0, band_high = 0.0;          // 95 % prediction interval (validation)
};

struct FigureSet {
  std::vector<FigureSweep> sweeps;
  // Drawn as figure_overview_jumps when the frequency sweeps' jumps span two
  // or more levels (else the amplitude sweeps' two or more frequencies).
  std::vector<OverviewJump> overview;
  std::vector<std::string> corner_lines;  // the estimates and the status, one per line
  std::string amplitude_unit = "data's unit";
  std::string control_unit;  // unit of a_base, for an amplitude sweep's x axis
  // What the sweeps' amplitude and level are (the test as run): "a" and
  // "base level a_base" for the model's form, e.g. "velocity amplitude" and
  // "force level" otherwise.
  std::string amplitude_name = "a";
  std::string level_name = "base level a_base";
  // The modal figure's amplitude is the displacement's: its unit (empty:
  // amplitude_unit).
  std::string displacement_unit;
  std::string residual_label;  // the fit's error measure, for the residual axis
  bool log_amplitude = false;  // the amplitude axis logarithmic
  // Drawn as figure_modal_properties when not empty: per amplitude a, the
  // natural frequency [Hz] and the damping ratio with their 95 % bands,
  // {a, omega_hz, low, high, zeta, low, high}.
  std::vector<std::array<double, 7>> modal;
};

inline constexpr char kOverviewFigureStem[] = "figure_overview_jumps";
inline constexpr char kModalFigureStem[] = "figure_modal_properties";

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

// Writes `inputs` (the script named kFigureScriptName and the files it reads)
// into a fresh temporary folder, runs gnuplot there for PNG and for SVG, the
// two side by side, and returns the images they made; the folder is removed. Never throws for a
// missing or failing gnuplot: the result then says why in `warning`.
RenderedFigures RenderFigures(const std::vector<NamedFile>& inputs);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_CURVES_FIGURES_H_
