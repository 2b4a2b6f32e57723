// One `identify` run as configured: resolve the run (resolved_run.h: the
// data loaded, labelled and selected, the start found), fit, report, and
// write result.yaml and predictions.csv into the output directory.
#ifndef DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_
#define DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_

#include <memory>
#include <ostream>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/identification_report.h"
#include "dwellfit/estimator/curves/figures.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {

// The resolved run (the report points into its sweeps) and the report.
struct IdentifyOutcome {
  ResolvedRun run;
  IdentificationReport report;
  std::vector<NamedFile> files;  // what the run writes: name and content
};

struct IdentifyRunOptions {
  bool render_figures = true;  // gnuplot's images (curves.csv and figures.gp either way)
  bool write_mat = false;      // result.mat too (as does the config's outputs: {mat: true})
};

// Runs the identification and writes its files; prints the config in effect
// and the summary to `out`. The report's result carries the run's status
// (FitStatus) with its reason; unidentifiable when the data cannot tell the
// free parameters apart. Throws InputError on bad input or when no fit could
// be made at all; nothing is written then.
std::unique_ptr<IdentifyOutcome> RunIdentify(const IdentifyConfig& config, std::ostream& out,
                                             const IdentifyRunOptions& options = {});

// RunIdentify without writing: the outcome with the files it would write,
// byte for byte (the Python module's identify).
std::unique_ptr<IdentifyOutcome> ComputeIdentify(const IdentifyConfig& config, std::ostream& out,
                                                 const IdentifyRunOptions& options = {});

// identify's exit status (README, "Exit status"):
inline constexpr int kExitConverged = 0;       // a converged, identifiable fit
inline constexpr int kExitInputError = 1;      // bad input, or no fit could be made
inline constexpr int kExitUsage = 2;           // bad command line
inline constexpr int kExitNoConvergence = 3;   // the fit stopped at its iteration limit
inline constexpr int kExitFailure = 4;         // the fit failed (status_message says why)
inline constexpr int kExitUnidentifiable = 5;  // the parameters cannot be told apart
// The exit status of a run that ended in `status`; with
// `accept_no_convergence` a fit stopped at its iteration limit exits 0.
int ExitStatusFor(FitStatus status, bool accept_no_convergence);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_IDENTIFY_RUN_H_
