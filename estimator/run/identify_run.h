// One `identify` run as configured: load the data, detect jumps and label
// branches, select the fitted and validation sweeps, fit, report, and write
// result.yaml and predictions.csv into the output directory.
#ifndef DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_
#define DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/config/sweep_selection.h"
#include "dwellfit/estimator/analysis/identification_report.h"
#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

// Loads every data file, checks that sweep names are unique across files,
// and detects jumps (which labels each dwell's branch).
std::vector<Sweep> LoadLabelledSweeps(const std::vector<std::string>& data_files,
                                      const JumpDetectionOptions& jump_detection);

// The sweeps `selections` name, in data order. Throws InputError naming
// `config_path` and `field` when a selection matches no sweep.
std::vector<const Sweep*> SelectSweeps(const std::vector<Sweep>& sweeps,
                                       const std::vector<SweepSelection>& selections,
                                       const std::string& config_path, const std::string& field);

// The sweeps a config names: every sweep of its data files, labelled (jump
// detection, then the config's `jumps:`), and the fitted and validation
// selections, which point into `sweeps` (so the struct moves, never copies).
struct ConfiguredSweeps {
  ConfiguredSweeps() = default;
  ConfiguredSweeps(ConfiguredSweeps&&) = default;
  ConfiguredSweeps& operator=(ConfiguredSweeps&&) = default;
  ConfiguredSweeps(const ConfiguredSweeps&) = delete;
  ConfiguredSweeps& operator=(const ConfiguredSweeps&) = delete;

  std::vector<Sweep> sweeps;
  std::vector<const Sweep*> fitted;
  std::vector<const Sweep*> validation;
};

// Loads, labels and selects as `config` says. Throws InputError.
ConfiguredSweeps LoadConfiguredSweeps(const IdentifyConfig& config);

// What a run produced: the sweeps it read (the report points into them) and
// the report it wrote.
struct IdentifyOutcome {
  ConfiguredSweeps sweeps;
  IdentificationReport report;
};

// Runs the identification and writes its files; prints the config in effect
// and the summary to `out`. Throws InputError on bad input or when the solver
// returns no usable solution (nothing is written then).
std::unique_ptr<IdentifyOutcome> RunIdentify(const IdentifyConfig& config, std::ostream& out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_
