// Sensitivity study (docs/sensitivity.md): the config fitted for every case
// of the Cartesian product of the `vary` axes, `replicas` times each (noisy
// replicas of a dwell plan; without a plan, the config's data once).
//
// Fit i = case * replicas + replica, stored by index, so the output does not
// depend on the thread count. A shard k/N runs the fits with i % N == k;
// MergeShards joins the shards' rows back into the order of one run.
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
  int dof = 0;                       // n - k: dwells fitted less free parameters (0: no fit)
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
  // CRC-32 (8 hex digits) of all that decides the fits (configs, plan, noise,
  // seeds, replicas, standard errors): shards merge only with their own.
  std::string fingerprint;
  std::vector<FitRow> rows;  // this shard's, by fit index
  double seconds = 0.0;
};

// Called after each fit with (done, of this shard).
using Progress = std::function<void(int done, int total)>;

// Throws InputError for a bad config, override, plan or option.
SensitivityStudy RunSensitivityStudy(const SensitivityOptions& options,
                                     const Progress& progress = nullptr);

// fits.csv and summary.yaml (docs/sensitivity.md).
std::string FitsToCsv(const SensitivityStudy& study);
std::string SummaryToYaml(const SensitivityStudy& study);

// fits.csv, summary.yaml, study.yaml (for MergeShards) and, with `figures`,
// figures.gp and gnuplot's images (no gnuplot: a line on `warnings`).
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
