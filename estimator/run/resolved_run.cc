#include "dwellfit/estimator/run/resolved_run.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/fit/initial_guess.h"
#include "dwellfit/estimator/matfile/mat_sweeps.h"

namespace dwellfit {
namespace {

// Every sweep of the data files; sweep names must be unique across files.
std::vector<Sweep> LoadSweeps(const std::vector<std::string>& data_files) {
  std::vector<Sweep> sweeps;
  std::map<std::string, std::string> file_of_sweep;
  for (const std::string& file : data_files) {
    LoadedSweeps loaded = IsMatFileName(file) ? LoadSweepsMat(file) : LoadSweepsCsv(file);
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
  return sweeps;
}

// Throws when the fitted sweeps hold no more dwells than there are free
// parameters: no degree of freedom would be left to estimate the noise.
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

// The settings the run uses before the fit (the fit's own options are
// checked where they enter it), so that a config built in code is checked.
// A fixed parameter's value must be the user's: held at an estimate from the
// data, it would bias every other parameter without a word.
void CheckSettings(const IdentifyConfig& config) {
  std::string message;
  if (!config.jump_detection.IsValid(&message)) {
    throw InputError(config.config_path, 0, "jump_detection", message);
  }
  for (int i = 0; i < kNumParameters; ++i) {
    if (!config.identification.fixed[i] || config.initial_guess[i]) continue;
    const char* name = ParameterName(config.identification.solve.residual.form, i);
    const std::string key = i == kNaturalFrequency ? "omega_hz" : name;
    throw InputError(config.config_path, 0, "fixed",
                     std::string(name) +
                         " is held fixed but its initial guess is left to the data (auto); give "
                         "initial_guess." +
                         key + ", or remove it from 'fixed'");
  }
}

// Fills the guesses the config leaves to the data into run->options.initial,
// estimated from the fitted sweeps with the given guesses as known.
void FillGuessesFromData(const IdentifyConfig& config, ResolvedRun* run) {
  const KnownParameters& given = config.initial_guess;
  run->guessed_from_data = std::any_of(given.begin(), given.end(),
                                       [](const std::optional<double>& value) { return !value; });
  if (!run->guessed_from_data) return;
  InitialGuessReport guess;
  try {
    guess = AutomaticInitialGuess(run->fitted, given, config.identification.solve.residual.form);
  } catch (const InputError& error) {
    throw InputError(config.config_path, 0, "initial_guess",
                     std::string("cannot find a starting point from the data: ") + error.what() +
                         "; give the initial guesses in the config");
  }
  for (int i = 0; i < kNumParameters; ++i) {
    if (!given[i]) run->options.initial[i] = guess.guess[i];
  }
  run->initial_guess_steps = std::move(guess.steps);
}

// The multi-start's automatic start (ResolvedRun::automatic_start).
void FindAutomaticStart(const IdentifyConfig& config, ResolvedRun* run) {
  if (config.multi_start.starts <= 1) return;
  KnownParameters fixed;
  for (int i = 0; i < kNumParameters; ++i) {
    if (config.identification.fixed[i]) fixed[i] = config.initial_guess[i];
  }
  try {
    InitialGuessReport guess =
        AutomaticInitialGuess(run->fitted, fixed, config.identification.solve.residual.form);
    run->automatic_start = guess.guess;
    run->automatic_start_steps = std::move(guess.steps);
  } catch (const InputError& error) {
    run->automatic_start_steps = {std::string("none (the multi-start does without it): ") +
                                  error.what()};
  }
}

// Maps the fitted and validation sweeps into the model's form with the
// stated or estimated phase offset (measured_quantity.h); the others are
// not used.
void MapToModelForm(const IdentifyConfig& config, ResolvedRun* run) {
  const TestQuantities& test = config.test;
  run->phase_offset_rad = test.phase_offset_rad;
  if (test.estimate_phase_offset) {
    const std::optional<double> estimate = EstimatePhaseOffset(test, run->fitted);
    if (!estimate) {
      throw InputError(config.config_path, 0, "phase.offset",
                       "cannot estimate the phase offset: no fitted frequency sweep has a measured "
                       "phase at its largest amplitude; state it with phase: {offset_deg: X}");
    }
    run->phase_offset_rad = *estimate;
    run->phase_note = StringPrintf(
        "phase offset %.2f deg estimated from the frequency sweeps' peaks (taken on the "
        "backbone, where the displacement lags the forcing by 90 deg; off by a few deg where the "
        "dwells near the peak are sparse): state it with phase: {offset_deg: X} when it is known",
        run->phase_offset_rad * 180.0 / kPi);
  } else if (test.phase_offset_rad != 0.0) {
    run->phase_note = StringPrintf("phase offset %.10g deg as stated (phase.offset_deg)",
                                   test.phase_offset_rad * 180.0 / kPi);
  }
  for (Sweep& sweep : run->sweeps) {
    const auto in = [&sweep](const std::vector<const Sweep*>& list) {
      return std::find(list.begin(), list.end(), &sweep) != list.end();
    };
    if (in(run->fitted) || in(run->validation)) ToModelForm(test, run->phase_offset_rad, &sweep);
  }
}

// The phase_lag stage reads the lag gamma of the displacement behind the
// forcing, which positive damping keeps in (0, 180) deg (docs/model.md,
// "Phase convention"). A fitted dwell's lag outside -10 to 190 deg (after
// the offset, wrapped) shows an offset or another convention in the file:
// refused rather than fitted.
void CheckPhaseConvention(const IdentifyConfig& config, const std::vector<const Sweep*>& fitted) {
  const auto& stages = config.identification.solve.stages;
  if (std::find(stages.begin(), stages.end(), ResidualKind::kPhaseLag) == stages.end()) return;
  for (const Sweep* sweep : fitted) {
    for (const DwellPoint& point : sweep->points) {
      if (!point.phase_rad || std::sin(*point.phase_rad) >= -std::sin(kPi / 18.0)) continue;
      const double lag_deg = std::remainder(*point.phase_rad, 2.0 * kPi) * 180.0 / kPi;
      throw InputError(
          sweep->source_file, point.source_line, "phase_deg",
          StringPrintf("the phase_lag stage needs the lag of the response behind the forcing, "
                       "which lies between 0 and 180 deg with positive damping; this dwell of "
                       "sweep '%s' gives %.1f deg (after the response's convention and the "
                       "offset %.2f deg): the phase column has an offset or another sign. State "
                       "it in the config with phase: {offset_deg: X}, or phase: {offset: "
                       "estimate} (docs/model.md, \"Phase convention\")",
                       sweep->Name().c_str(), lag_deg, config.test.phase_offset_rad * 180.0 / kPi));
    }
  }
}

}  // namespace

std::string SecondOrderRangeProblem(const ResolvedRun& run, double natural_frequency_rad_s) {
  if (!run.options.solve.residual.form.second_order()) return "";
  const double lowest = kSecondOrderMinFrequencyRatio * natural_frequency_rad_s;
  for (const auto* sweeps : {&run.fitted, &run.validation}) {
    for (const Sweep* sweep : *sweeps) {
      for (const DwellPoint& point : sweep->points) {
        if (point.drive_frequency_rad_s >= lowest) continue;
        return StringPrintf(
            "%s:%d: sweep '%s' has a dwell at %.6g Hz, below %.2g w = %.6g Hz, where the "
            "second-order model's terms (1 / (9 Omega^2 - w^2), the superharmonic resonance at "
            "w/3) are not valid; use model: {averaging: first_order} or leave these dwells out",
            sweep->source_file.c_str(), point.source_line, sweep->Name().c_str(),
            RadPerSecondToHz(point.drive_frequency_rad_s), kSecondOrderMinFrequencyRatio,
            RadPerSecondToHz(lowest));
      }
    }
  }
  return "";
}

std::vector<const Sweep*> SelectSweeps(const std::vector<Sweep>& sweeps,
                                       const std::vector<SweepSelection>& selections,
                                       const std::string& config_path, const std::string& field) {
  for (const SweepSelection& selection : selections) {
    const auto selects = [&](const Sweep& sweep) { return selection.Selects(sweep); };
    if (std::none_of(sweeps.begin(), sweeps.end(), selects)) {
      std::string available;
      for (const Sweep& sweep : sweeps) available += (available.empty() ? "" : ", ") + sweep.Name();
      throw InputError(
          config_path, 0, field,
          "sweep '" + selection.Name() + "' is not in the data; available: " + available);
    }
  }
  std::vector<const Sweep*> selected;
  for (const Sweep& sweep : sweeps) {
    const auto selects = [&](const SweepSelection& selection) { return selection.Selects(sweep); };
    if (std::any_of(selections.begin(), selections.end(), selects)) selected.push_back(&sweep);
  }
  return selected;
}

ResolvedRun ResolveRun(const IdentifyConfig& config) {
  return ResolveRun(config, LoadSweeps(config.data_files));
}

ResolvedRun ResolveRun(const IdentifyConfig& config, std::vector<Sweep> sweeps) {
  CheckSettings(config);
  ResolvedRun run;
  run.sweeps = std::move(sweeps);
  DetectJumps(config.jump_detection, &run.sweeps);
  ApplyJumpOverrides(config.jump_overrides, config.config_path, &run.sweeps);
  run.fitted = SelectSweeps(run.sweeps, config.fit_sweeps, config.config_path, "fit");
  run.validation = SelectSweeps(run.sweeps, config.validate_sweeps, config.config_path, "validate");
  MapToModelForm(config, &run);
  CheckEnoughDwells(config, run.fitted);
  CheckPhaseConvention(config, run.fitted);
  run.options = config.identification;
  run.multi_start = config.multi_start;
  FillGuessesFromData(config, &run);
  FindAutomaticStart(config, &run);
  // A start found from the data is new input: checked here, with what to do.
  std::string invalid;
  if (run.guessed_from_data && !run.options.InitialIsValid(&invalid)) {
    throw InputError(config.config_path, 0, "initial_guess",
                     "the starting point is not usable (" + invalid +
                         "); give the initial guesses in the config");
  }
  // The second order is refused, before any fit, where a dwell lies below
  // its range at the start's natural frequency.
  const std::string range = SecondOrderRangeProblem(run, run.options.initial[kNaturalFrequency]);
  if (!range.empty()) throw InputError(config.config_path, 0, "model.averaging", range);
  return run;
}

MultiStartResult FitRun(const ResolvedRun& run) {
  return IdentifyMultiStart(run.fitted, run.options, run.automatic_start, run.multi_start);
}

}  // namespace dwellfit
