// Sensitivity study: many fits of one config, varying what the caller says.
//
// Cases are the Cartesian product of the `vary` axes, each axis a config key
// with a list of values (any key identify's --set accepts: the penalty
// exponent, weight and Lambda, multi_start.starts (random starts), an
// initial_guess of a fixed parameter (a profile), `fixed`, `fit`, ...). Each
// case is fitted `replicas` times: with a dwell plan, replica r simulates the
// plan with relative noise `noise` and seed first_seed + r (as the coverage
// study does); without one, the config's own data (one replica). Every fit
// takes the one path of a measured run (resolved_run.h: ResolveRun, FitRun)
// and the uncertainty at its estimate.
//
// Fit i = case * replicas + replica; fits run on `threads` threads (each fit
// single-threaded) into slots by index, so the output does not depend on the
// thread count. A shard k/N runs the fits with i % N == k; MergeShards joins
// the shards' rows back into the order of one run.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_SENSITIVITY_STUDY_H_
#define DWELLFIT_ESTIMATOR_STUDIES_SENSITIVITY_STUDY_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {

// One varied key and its values (YAML text each).
struct VaryAxis {
  std::string key;
  std::vector<std::string> values;
};

// Parses "key=v1|v2|v3;key2=w1|w2" (axes split at ';' outside brackets,
// values at '|'). Throws InputError naming `origin` for an empty key or value.
std::vector<VaryAxis> ParseVaryFlag(const std::string& flag_value, const std::string& origin);

struct SensitivityOptions {
  std::string config_path;
  std::vector<ConfigOverride> overrides;  // --set etc., applied to every case
  std::vector<VaryAxis> vary;
  std::optional<DwellPlan> plan;  // none: the config's data
  int replicas = 1;
  double noise = 0.0;  // relative sigma with a plan
  std::uint64_t first_seed = 1;
  int threads = 1;
  int shard = 0, shards = 1;    // run the fits with i % shards == shard
  bool standard_errors = true;  // ceres::Covariance at every estimate

  bool IsValid(std::string* why) const;
};

// One fit's row of fits.csv.
struct FitRow {
  int fit = 0;
  int case_index = 0;
  int replica = 0;
  std::uint64_t seed = 0;             // 0 without a plan
  std::vector<std::string> settings;  // the case's value of each axis
  std::string status;                 // FitStatusName
  double cost = 0.0;
  int iterations = 0;
  ParameterVector estimate{};        // omega in Hz
  ParameterVector standard_error{};  // 0 where unavailable or fixed (omega in Hz)
};

struct SensitivityStudy {
  std::vector<std::string> axis_keys;
  int cases = 0;
  int replicas = 0;
  int total_fits = 0;  // of the whole study (all shards)
  int shard = 0, shards = 1;
  std::optional<ParameterVector> truth;  // the plan's (omega in Hz)
  // CRC-32 (8 hex digits) of everything that decides the fits: each case's
  // config in effect, the plan, the noise, the seeds, the replicas and the
  // standard-error switch. Shards merge only with their own study's.
  std::string fingerprint;
  std::vector<FitRow> rows;  // this shard's, by fit index
  double seconds = 0.0;
};

// Called after each fit with (done, of this shard).
using Progress = std::function<void(int done, int total)>;

// Runs the study. Throws InputError for a bad config, override, plan or
// option (naming the flag or file).
SensitivityStudy RunSensitivityStudy(const SensitivityOptions& options,
                                     const Progress& progress = nullptr);

// fits.csv: fit,case,replica,seed,<axis keys>,status,cost,iterations, then
// value and _se of eta_e, mu1, mu2, delta, alpha, omega_hz.
std::string FitsToCsv(const SensitivityStudy& study);
// study.yaml: what MergeShards needs (keys, sizes, shard, truth).
std::string StudyToYaml(const SensitivityStudy& study);
// summary.yaml: per case, the fits, how many are usable and converged, the
// success rate, and per parameter mean, standard deviation, mean standard
// error and, with a truth, the bias.
std::string SummaryToYaml(const SensitivityStudy& study);
// sensitivity.gp: histograms of every estimate per case and, with one axis,
// the profile: the mean cost and every estimate against the axis value.
std::string StudyFigureScript(const SensitivityStudy& study);

// The files of a study's output folder: fits.csv, summary.yaml, study.yaml
// and, with `figures`, figures.gp and the histogram (and profile) images
// gnuplot draws from it; a missing or failing gnuplot is a line on
// `warnings`, never an error.
std::vector<std::pair<std::string, std::string>> StudyFiles(const SensitivityStudy& study,
                                                            bool figures, std::ostream& warnings);

// A Progress that draws a bar on `out` (a terminal: rewritten in place) or
// prints a plain line at every tenth (not a terminal). Thread-safe.
Progress MakeProgressPrinter(std::ostream& out, bool terminal);

// Reads the study.yaml and fits.csv of each shard folder and joins them;
// throws InputError unless they are the shards 0..N-1 of one study.
SensitivityStudy MergeShards(const std::vector<std::string>& folders);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_SENSITIVITY_STUDY_H_
