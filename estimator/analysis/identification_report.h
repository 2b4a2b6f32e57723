// What an identification run reports (result.yaml, predictions.csv and a
// printed summary): the estimates, how the solver ended, and the model beside
// every measured dwell.
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_IDENTIFICATION_REPORT_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_IDENTIFICATION_REPORT_H_

#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/level_refits.h"
#include "dwellfit/estimator/analysis/modal_properties.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/analysis/prediction_intervals.h"
#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/multi_start.h"

namespace dwellfit {

struct IdentificationReport {
  std::string config_path;
  std::string config_in_effect;   // a YAML block mapping, in result.yaml when set
  IdentificationOptions options;  // the start and the fixed parameters
  IdentificationResult result;
  double omega_ref_rad_s = 0.0;              // Omega_ref of alpha_e
  std::vector<SweepPrediction> predictions;  // fitted sweeps first, then validation
  // How the automatic starting point was found (empty: every guess given).
  std::vector<std::string> initial_guess_steps;
  // The starts and how many reached the best (one start: trivially 1 of 1).
  MultiStartResult multi_start;
  ParameterUncertainty uncertainty;
  // Model error (docs/uncertainty.md), set by AddModelError.
  ValidationIntervals validation_intervals;
  LevelRefits level_refits;
  // omega(a) and zeta(a) over the fitted amplitudes (modal_properties.h).
  ModalProperties modal;
};

// Fills report->validation_intervals and report->level_refits.
void AddModelError(const std::vector<const Sweep*>& fitted,
                   const std::vector<const Sweep*>& validation, int threads,
                   IdentificationReport* report);

// result.yaml (docs/outputs.md; omega in rad/s).
std::string ReportToYaml(const IdentificationReport& report);

// predictions.csv: one row per measured dwell with the model's amplitude.
std::string ReportToPredictionsCsv(const IdentificationReport& report);

// The human summary: solver line per stage, table of estimates, per-sweep RMS.
void PrintReport(const IdentificationReport& report, std::ostream& out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_IDENTIFICATION_REPORT_H_
