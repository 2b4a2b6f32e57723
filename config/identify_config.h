// The configuration of one `identify` run, read from a YAML file (schema and
// every key documented in config/README.md) plus command-line overrides.
//
// Loading is strict: an unknown or repeated key, a value of the wrong type, a
// missing required key or an invalid value throws InputError naming the file,
// the 1-based line and the key path, or the flag of the override that set it.
#ifndef DWELLFIT_CONFIG_IDENTIFY_CONFIG_H_
#define DWELLFIT_CONFIG_IDENTIFY_CONFIG_H_

#include <optional>
#include <string>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/model_selection_config.h"
#include "dwellfit/config/sweep_selection.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/data/measured_quantity.h"
#include "dwellfit/estimator/fit/forcing_calibration.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/initial_guess.h"
#include "dwellfit/estimator/fit/multi_start.h"

namespace dwellfit {

struct DataUnits {
  std::string a;       // of the response amplitude a (and its sigma)
  std::string a_base;  // of the base level a_base
};

// The units of the model's form (docs/model.md, "The test as run"), in which
// the parameters are: the displacement's, `units.a` times s^p (m/s -> m,
// m/s^2 -> m), and the level's, `units.a_base` per s^q (base displacement
// m -> m/s^2). Unstated units are [A] (displacement), [V] (velocity),
// [Acc] (acceleration) and [B] (level).
DataUnits ModelFormUnits(const DataUnits& units, const TestQuantities& test);

struct IdentifyConfig {
  // The config file, absolute.
  std::string config_path;
  // Data files, absolute: resolved relative to the config file's directory
  // (relative to the working directory when an override gave them). Each exists.
  std::vector<std::string> data_files;
  // Sweeps fitted; non-empty, no sweep selected twice.
  std::vector<SweepSelection> fit_sweeps;
  // Sweeps only predicted and scored; none of them is also fitted.
  std::vector<SweepSelection> validate_sweeps;
  // The test as run (`excitation:`, `response:`, `phase:`): how the sweeps
  // map into the model's form (measured_quantity.h). The defaults are the
  // model's own form; identification.solve.residual.response_power follows
  // `response`.
  TestQuantities test;
  // The initial guesses the config gives (physical units, omega in rad/s);
  // an entry left out or `auto` is found from the data (initial_guess.h).
  KnownParameters initial_guess;
  // Fixed parameters, fit stages, residual, penalty and solver settings;
  // `initial` holds the given guesses and placeholders for the automatic
  // ones until the run fills them. IsValid() holds.
  IdentificationOptions identification;
  // Fits from several starts (multi_start.h); one start by default.
  MultiStartOptions multi_start;
  JumpDetectionOptions jump_detection;
  // Jumps stated per sweep (`jumps:`), applied after detection
  // (ApplyJumpOverrides); frequencies in rad/s, one entry per sweep at most.
  // Whether each names a sweep of the data is checked when the data is read.
  std::vector<JumpOverride> jump_overrides;
  // Omega_ref [rad/s] of the effective nonlinearity alpha - (2/3) delta
  // Omega_ref^2; unset: the identified omega.
  std::optional<double> omega_ref_rad_s;
  // Where results go, absolute (resolved like data_files); may not exist yet.
  std::string output_dir;
  // The names of the data's units in figures and reports (`units: {a: mm,
  // a_base: g}`); empty: unstated. They change no number.
  DataUnits units;
  // `plot: {log_amplitude: true}`: the figures' amplitude axes logarithmic.
  bool log_amplitude = false;
  // `outputs: {mat: true}`: also write result.mat (docs/matlab.md).
  bool write_mat = false;
  // The model variants to compare and how (`model_selection:`); unset when
  // the config has no such block. `identify` ignores it; `select_model` runs it.
  std::optional<ModelSelectionConfig> model_selection;
  // Per-sweep forcing calibration (`forcing_calibration: {prior_sigma: 0.05,
  // held_out_dwells: before_jump}`, fit/forcing_calibration.h); unset when the
  // config has no such block. `identify` ignores it; `forcing_calibration`
  // runs it.
  std::optional<ForcingCalibrationOptions> forcing_calibration;
  // The overrides applied on top of the file, in order.
  std::vector<ConfigOverride> overrides;
};

// Reads, overrides and validates the config at `path`. `overrides` are applied
// to the YAML tree before validation, so they pass the same checks.
IdentifyConfig LoadIdentifyConfig(const std::string& path,
                                  const std::vector<ConfigOverride>& overrides = {});

// The same for YAML text (JSON is YAML too) named `name` in errors, its
// relative paths taken from `base_dir` (the Python module's dict configs).
IdentifyConfig ParseIdentifyConfig(const std::string& name, const std::string& yaml_text,
                                   const std::string& base_dir,
                                   const std::vector<ConfigOverride>& overrides = {});

// Which keys ConfigToYaml writes.
enum class ConfigKeys {
  // Every key, after a comment naming the source file and the overrides.
  kAll,
  // Only the keys that can change the result: without output_dir,
  // solver.num_threads and multi_start.threads, and without the comment, so
  // that one input gives one result.yaml wherever it is written and on any
  // thread count.
  kAffectingTheResult,
};

// The config in effect as YAML text that LoadIdentifyConfig accepts again
// (for printing, and for result.yaml's provenance). Paths are absolute;
// omega is in Hz.
std::string ConfigToYaml(const IdentifyConfig& config, ConfigKeys keys = ConfigKeys::kAll);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_IDENTIFY_CONFIG_H_
