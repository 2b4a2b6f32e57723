#include "dwellfit/estimator/run/identify_run.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "dwellfit/estimator/fit/initial_guess.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/fit/multi_start.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "glog/logging.h"

namespace dwellfit {

std::vector<Sweep> LoadLabelledSweeps(const std::vector<std::string>& data_files,
                                      const JumpDetectionOptions& jump_detection) {
  std::vector<Sweep> sweeps;
  std::map<std::string, std::string> file_of_sweep;
  for (const std::string& file : data_files) {
    LoadedSweeps loaded = LoadSweepsCsv(file);
    for (Sweep& sweep : loaded.sweeps) {
      const auto [it, inserted] = file_of_sweep.emplace(sweep.Name(), file);
      if (!inserted) {
        throw InputError(file, sweep.points.front().source_line, "sweep",
                         "sweep '" + sweep.Name() + "' also appears in " + it->second +
                             "; give the sweeps of different files different ids");
      }
      sweeps.push_back(std::move(sweep));
    }
  }
  DetectJumps(jump_detection, &sweeps);
  return sweeps;
}

std::vector<const Sweep*> SelectSweeps(const std::vector<Sweep>& sweeps,
                                       const std::vector<SweepSelection>& selections,
                                       const std::string& config_path, const std::string& field) {
  for (const SweepSelection& selection : selections) {
    bool found = false;
    for (const Sweep& sweep : sweeps) found = found || selection.Selects(sweep);
    if (!found) {
      std::string available;
      for (const Sweep& sweep : sweeps) available += (available.empty() ? "" : ", ") + sweep.Name();
      throw InputError(
          config_path, 0, field,
          "sweep '" + selection.Name() + "' is not in the data; available: " + available);
    }
  }
  std::vector<const Sweep*> selected;
  for (const Sweep& sweep : sweeps) {
    for (const SweepSelection& selection : selections) {
      if (selection.Selects(sweep)) {
        selected.push_back(&sweep);
        break;
      }
    }
  }
  return selected;
}

namespace {

// Throws when the fitted sweeps hold no more dwells than there are free
// parameters: such a fit interpolates (or is underdetermined) and has no
// degree of freedom left to estimate the noise, so no usable result.
void CheckEnoughDwells(const IdentifyConfig& config, const std::vector<const Sweep*>& fitted) {
  std::size_t dwells = 0;
  for (const Sweep* sweep : fitted) dwells += sweep->points.size();
  const auto free = static_cast<std::size_t>(
      std::count(config.identification.fixed.begin(), config.identification.fixed.end(), false));
  if (dwells > free) return;
  std::string names;
  for (const Sweep* sweep : fitted) {
    names += (names.empty() ? "" : ", ") + sweep->Name() + " (" +
             std::to_string(sweep->points.size()) + ")";
  }
  throw InputError(config.config_path, 0, "fit",
                   "the fitted sweeps hold " + std::to_string(dwells) + " measured dwell(s) (" +
                       names + ") for " + std::to_string(free) +
                       " free parameters; a fit needs more dwells than free parameters: fit more "
                       "sweeps, or fix parameters (fixed: with their initial_guess)");
}

// Throws when the best start is no usable estimate: a stage could not
// evaluate its cost (every start failed), or the estimate is not finite.
void CheckUsable(const IdentifyConfig& config, const MultiStartResult& multi_start) {
  const IdentificationResult& result = multi_start.best;
  if (!result.failure.empty()) {
    throw InputError(
        config.config_path, 0, "initial_guess",
        "the fit cannot proceed: " + result.failure +
            (multi_start.starts.size() > 1 ? " (and every other start failed too)" : "") +
            "; give initial guesses closer to the data (initial_guess, config/README.md), or "
            "check the dwells named");
  }
  if (multi_start.failed > 0) {
    LOG(WARNING) << multi_start.failed << " of " << multi_start.starts.size()
                 << " starts failed (their cost could not be evaluated); the best of the others "
                    "is kept";
  }
  for (double value : result.parameters) {
    if (!std::isfinite(value)) {
      throw InputError(config.config_path, 0, "initial_guess",
                       "the solver returned no usable solution; start closer to the data "
                       "(see config/README.md, initial_guess)");
    }
  }
}

}  // namespace

ConfiguredSweeps LoadConfiguredSweeps(const IdentifyConfig& config) {
  ConfiguredSweeps configured;
  configured.sweeps = LoadLabelledSweeps(config.data_files, config.jump_detection);
  ApplyJumpOverrides(config.jump_overrides, config.config_path, &configured.sweeps);
  configured.fitted = SelectSweeps(configured.sweeps, config.fit_sweeps, config.config_path, "fit");
  configured.validation =
      SelectSweeps(configured.sweeps, config.validate_sweeps, config.config_path, "validate");
  CheckEnoughDwells(config, configured.fitted);
  return configured;
}

std::unique_ptr<IdentifyOutcome> RunIdentify(const IdentifyConfig& config, std::ostream& out) {
  out << "# config in effect\n" << ConfigToYaml(config) << "\n";
  CheckOutputDirectory(config.output_dir, "output_dir");
  auto outcome = std::make_unique<IdentifyOutcome>();
  outcome->sweeps = LoadConfiguredSweeps(config);
  const std::vector<const Sweep*>& fitted = outcome->sweeps.fitted;
  const std::vector<const Sweep*>& validation = outcome->sweeps.validation;
  for (const Sweep* sweep : fitted) out << "fit      " << DescribeJumps(*sweep) << "\n";
  for (const Sweep* sweep : validation) out << "validate " << DescribeJumps(*sweep) << "\n";
  out << "\n";

  // Guesses the config leaves to the data; the automatic start is also one
  // of the multi-start's starts.
  IdentificationOptions options = config.identification;
  std::vector<std::string> guess_steps;
  std::optional<ParameterVector> automatic;
  const bool any_automatic = std::any_of(config.initial_guess.begin(), config.initial_guess.end(),
                                         [](const std::optional<double>& v) { return !v; });
  if (any_automatic || config.multi_start.starts > 1) {
    try {
      const InitialGuessReport guess = AutomaticInitialGuess(fitted, config.initial_guess);
      automatic = guess.guess;
      guess_steps = guess.steps;
    } catch (const InputError& error) {
      if (any_automatic) {
        throw InputError(config.config_path, 0, "initial_guess",
                         std::string("cannot find a starting point from the data: ") +
                             error.what() + "; give the initial guesses in the config");
      }
    }
    if (any_automatic) {
      for (int i = 0; i < kNumParameters; ++i) {
        if (!config.initial_guess[i]) options.initial[i] = (*automatic)[i];
      }
      out << "automatic initial guess:\n";
      for (const std::string& step : guess_steps) out << "  " << step << "\n";
      out << "\n";
    }
  }
  std::string invalid;
  if (!options.IsValid(&invalid)) {
    throw InputError(config.config_path, 0, "initial_guess",
                     "the starting point is not usable (" + invalid +
                         "); give the initial guesses in the config");
  }
  const MultiStartResult multi_start =
      IdentifyMultiStart(fitted, options, automatic, config.multi_start);
  const IdentificationResult& result = multi_start.best;
  CheckUsable(config, multi_start);
  options.initial = multi_start.starts[multi_start.best_start];
  outcome->report =
      MakeIdentificationReport(config.config_path, options, result,
                               config.omega_ref_rad_s.value_or(0.0), fitted, validation);
  outcome->report.initial_guess_steps = guess_steps;
  outcome->report.multi_start = multi_start;
  outcome->report.uncertainty =
      EstimateUncertainty(fitted, options, result.parameters, outcome->report.omega_ref_rad_s);
  const IdentificationReport& report = outcome->report;
  PrintReport(report, out);
  WriteFilesAtomically(config.output_dir, {{"result.yaml", ReportToYaml(report)},
                                           {"predictions.csv", ReportToPredictionsCsv(report)}});
  out << "\nwrote " << config.output_dir << "/result.yaml and predictions.csv (listed in "
      << kManifestFileName << ")\n";
  return outcome;
}

}  // namespace dwellfit
