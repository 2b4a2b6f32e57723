// The one path from a config to a fit, taken by `identify`, the studies and
// the benchmarks alike. ResolveRun reads the sweeps (or takes simulated ones),
// labels their jumps (DetectJumps, then the config's `jumps:`), selects the
// `fit` and `validate` sweeps, finds the guesses the config leaves to the data
// (AutomaticInitialGuess; for a multi-start also the automatic start) and
// checks the start; FitRun fits from there (IdentifyMultiStart).
#ifndef DWELLFIT_ESTIMATOR_RUN_RESOLVED_RUN_H_
#define DWELLFIT_ESTIMATOR_RUN_RESOLVED_RUN_H_

#include <optional>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/multi_start.h"

namespace dwellfit {

// `fitted` and `validation` point into `sweeps`: the struct moves, never copies.
struct ResolvedRun {
  ResolvedRun() = default;
  ResolvedRun(ResolvedRun&&) = default;
  ResolvedRun& operator=(ResolvedRun&&) = default;
  ResolvedRun(const ResolvedRun&) = delete;
  ResolvedRun& operator=(const ResolvedRun&) = delete;

  // Every sweep, its branches labelled; the selections in data order, in
  // the model's form (a displacement response to a base acceleration:
  // ToModelForm of the config's `test`; the unselected sweeps as measured).
  std::vector<Sweep> sweeps;
  std::vector<const Sweep*> fitted;
  std::vector<const Sweep*> validation;
  // The config's options with `initial` complete (omega in rad/s). A caller
  // may change the solver's thread count or switch penalties off before FitRun.
  IdentificationOptions options;
  MultiStartOptions multi_start;
  // Whether some initial guess came from the data, and how those were found
  // (one line per step, initial_guess.h; empty when every guess is given).
  bool guessed_from_data = false;
  std::vector<std::string> initial_guess_steps;
  // With multi_start.starts > 1, the multi-start's second start: every free
  // parameter found from the data, the fixed ones given; unset when the
  // sweeps show no resonance to estimate from (its step says so).
  std::optional<ParameterVector> automatic_start;
  std::vector<std::string> automatic_start_steps;
  // The phase columns' offset [rad] taken off by ToModelForm: the stated one,
  // or the estimate; `phase_note` says which (empty without `phase:`).
  double phase_offset_rad = 0.0;
  std::string phase_note;
};

// Reads the config's data files (sweep ids unique across files) and resolves
// the run on them. Throws InputError naming the file and the field.
ResolvedRun ResolveRun(const IdentifyConfig& config);

// The same on sweeps already in memory (e.g. simulated from a dwell plan).
ResolvedRun ResolveRun(const IdentifyConfig& config, std::vector<Sweep> sweeps);

// The sweeps `selections` name, in data order. Throws InputError naming
// `config_path` and `field` when a selection matches no sweep.
std::vector<const Sweep*> SelectSweeps(const std::vector<Sweep>& sweeps,
                                       const std::vector<SweepSelection>& selections,
                                       const std::string& config_path, const std::string& field);

// Fits the run's fitted sweeps from its start (IdentifyMultiStart).
MultiStartResult FitRun(const ResolvedRun& run);

// With the second-order model (model_form.h): a message naming the first
// fitted or validation dwell below kSecondOrderMinFrequencyRatio times
// `natural_frequency_rad_s` (its file and line); empty when there is none or
// the model is the first order. ResolveRun refuses such a run at its start;
// identify warns when the estimate's w puts a dwell there.
std::string SecondOrderRangeProblem(const ResolvedRun& run, double natural_frequency_rad_s);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_RESOLVED_RUN_H_
