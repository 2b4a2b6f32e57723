// next_dwell: where to dwell next. Fits the config's sweeps (the dwells so
// far), then ranks the candidate next dwells within the rig's limits by the
// expected gain per second of test time (estimator/design/next_dwell.h,
// docs/next-dwell.md); prints the best with the expected intervals after
// each and writes next_dwell.csv and a figure of the gain.
#include <iostream>
#include <string>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/design/next_dwell_run.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"

DEFINE_string(config, "", "identify config YAML of the dwells so far (required)");
DEFINE_string(state, "",
              "the rig now (required): f_hz=<Hz>,level=<base level>,branch=upper|lower|only");
DEFINE_string(limits, "",
              "the rig's limits, any of f_min_hz, f_max_hz, f_step_min_hz, f_step_max_hz, "
              "level_min, level_max, level_step_min, level_step_max as key=value,...; the rest "
              "from the fitted sweeps' span and smallest spacing");
DEFINE_string(target, "d_optimal",
              "what to learn: d_optimal (all free parameters), a parameter (eta_e, mu1, mu2, "
              "delta, alpha, omega), alpha_e, omega_at=<amplitude> or jump_up_hz|jump_down_hz="
              "<level>");
DEFINE_double(
    settle_time_constants, 5.0,
    "k of the settling time (k + ln(1 + relative amplitude step)) / (mu1 + (2/pi) mu2 a) [s]");
DEFINE_double(recording_seconds, 2.0, "recording time of one dwell [s]");
DEFINE_double(noise_sigma, 0.0,
              "noise of a new dwell in the residual's unit (0: the fit's own residual noise)");
DEFINE_int32(top, 5, "candidates printed with their expected intervals");
DEFINE_int32(segment_dwells, 1,
             "n >= 2: also rank segments of n dwells stepping along one axis, up or down "
             "(1: single dwells only; at most 20)");
DEFINE_string(set, "", "config overrides, as identify's --set");
DEFINE_string(output_dir, ".", "folder for next_dwell.csv, next_dwell.gp and the figure");
DEFINE_bool(figures, true, "render the figure with gnuplot");

namespace {

dwellfit::NextDwellRequest RequestFromFlags() {
  dwellfit::DesignOptions options;
  options.settle_time_constants = FLAGS_settle_time_constants;
  options.recording_seconds = FLAGS_recording_seconds;
  options.noise_sigma = FLAGS_noise_sigma;
  options.top = FLAGS_top;
  options.segment_dwells = FLAGS_segment_dwells;
  dwellfit::NextDwellRequest request =
      dwellfit::MakeNextDwellRequest(FLAGS_state, FLAGS_limits, FLAGS_target, options, "--");
  request.render_figures = FLAGS_figures;
  return request;
}

}  // namespace

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "next_dwell",
      "ranks the candidate next dwells of a sine-dwell test by the expected gain per second.\n"
      "  next_dwell --config beam.yaml --state f_hz=41.5,level=0.01,branch=upper\n"
      "             [--limits f_step_max_hz=1,level_step_max=0.01] [--target alpha_e]\n"
      "See docs/next-dwell.md.",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_config.empty() || FLAGS_state.empty()) {
      std::cerr << "next_dwell: give --config FILE and --state f_hz=...,level=...; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    const dwellfit::NextDwellRequest request = RequestFromFlags();
    dwellfit::CheckOutputDirectory(FLAGS_output_dir, "--output_dir");
    const dwellfit::IdentifyConfig config =
        dwellfit::LoadIdentifyConfig(FLAGS_config, dwellfit::ParseSetFlag(FLAGS_set, "--set"));
    const dwellfit::NextDwellOutcome outcome =
        dwellfit::ComputeNextDwell(config, request, std::cout);
    const dwellfit::FitStatus status = outcome.fit.status;
    const int exit_status = dwellfit::ExitStatusFor(status, false);
    if (status != dwellfit::FitStatus::kConverged &&
        status != dwellfit::FitStatus::kNoConvergence) {
      std::cerr << "next_dwell: status " << dwellfit::FitStatusName(status) << " (exit "
                << exit_status << "): " << outcome.fit.message << "; no recommendation\n";
      return exit_status;
    }
    dwellfit::WriteFilesAtomically(FLAGS_output_dir, outcome.files);
    std::cout << "wrote " << FLAGS_output_dir << "/" << dwellfit::kNextDwellCsvName << " ("
              << outcome.recommendation.ranked.size() << " candidates)\n";
    if (outcome.recommendation.ranked.empty()) {
      std::cerr << "next_dwell: no candidate within the limits has a stable response; widen "
                   "--limits\n";
      return dwellfit::kExitFailure;
    }
    if (status == dwellfit::FitStatus::kNoConvergence) {
      std::cerr << "next_dwell: status no_convergence (exit 3): the fit stopped at its iteration "
                   "limit, so the ranking is from an estimate that is not a proven minimum\n";
    }
    return exit_status;
  });
}
