// The one path from a config to a fit, taken by `identify`, the chapter's
// tables, the coverage study and the benchmark alike.
//
// ResolveRun turns an IdentifyConfig into a run ready to fit:
//   1. sweeps: read from the config's data files (or given: simulated replicas);
//   2. labelled: jumps detected in every sweep (DetectJumps), then replaced
//      where the config states them (`jumps:`, ApplyJumpOverrides);
//   3. selected: the `fit` and `validate` sweeps;
//   4. started: the initial guesses the config leaves to the data found from
//      the fitted sweeps (AutomaticInitialGuess), with how each was found,
//      and for a multi-start the automatic start;
//   5. checked: the options with their start filled in are usable, and
//      every fixed parameter has a given value.
// FitRun then fits from that start: IdentifyMultiStart with the config's
// `multi_start` (one start by default).
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

// A config resolved into a run. `fitted` and `validation` point into
// `sweeps`, so the struct moves (the pointers stay valid) but never copies.
struct ResolvedRun {
  ResolvedRun() = default;
  ResolvedRun(ResolvedRun&&) = default;
  ResolvedRun& operator=(ResolvedRun&&) = default;
  ResolvedRun(const ResolvedRun&) = delete;
  ResolvedRun& operator=(const ResolvedRun&) = delete;

  std::string config_path;  // for errors and reports
  // Every sweep, its branches labelled; the selections in data order.
  std::vector<Sweep> sweeps;
  std::vector<const Sweep*> fitted;
  std::vector<const Sweep*> validation;
  // The config's options with `initial` complete: the given guesses and the
  // automatic ones (omega in rad/s). Valid (IsValid). A caller may change the
  // solver's thread count or switch penalties off before FitRun.
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
};

// Reads the config's data files (sweep ids unique across files) and resolves
// the run on them. Throws InputError naming the file and the field.
ResolvedRun ResolveRun(const IdentifyConfig& config);

// The same on sweeps already in memory (e.g. simulated from a dwell plan).
ResolvedRun ResolveRun(const IdentifyConfig& config, std::vector<Sweep> sweeps);

// Fits the run's fitted sweeps from its start (IdentifyMultiStart).
MultiStartResult FitRun(const ResolvedRun& run);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_RESOLVED_RUN_H_
