// One `identify` run as configured: resolve the run (resolved_run.h: the
// data loaded, labelled and selected, the start found), fit, report, and
// write result.yaml and predictions.csv into the output directory.
#ifndef DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_
#define DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_

#include <memory>
#include <ostream>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/identification_report.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {

// What a run produced: the resolved run (the report points into its sweeps)
// and the report it wrote.
struct IdentifyOutcome {
  ResolvedRun run;
  IdentificationReport report;
};

// Runs the identification and writes its files; prints the config in effect
// and the summary to `out`. Throws InputError on bad input or when the solver
// returns no usable solution (nothing is written then).
std::unique_ptr<IdentifyOutcome> RunIdentify(const IdentifyConfig& config, std::ostream& out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_
