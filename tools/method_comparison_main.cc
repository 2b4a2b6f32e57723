// method_comparison: writes the comparison of the chapter's methods (phase
// lag, least squares on eq. 3.11, all roots, Newton refinement) on the
// numerical case (exact and noisy), on measured data and, beside harmonic
// balance, on the virtual beam's time traces, as Markdown.
#include <iostream>
#include <optional>
#include <string>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/studies/method_comparison.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(numerical, "datasets/thesis-numerical/beam.yaml",
              "Config on simulated data with a phase column (Table 3.1)");
DEFINE_string(truth_plan, "datasets/thesis-numerical/plan.yaml",
              "Dwell plan the numerical data were simulated from: truth and sweeps");
DEFINE_string(measured, "datasets/clamped-beam-27C/beam.yaml",
              "Config on measured data (Table 3.2)");
DEFINE_string(traces, "datasets/virtual-beam/traces",
              "Folder of time traces with a known truth (harmonic balance beside the methods); "
              "empty: no such section");
DEFINE_string(traces_config, "datasets/virtual-beam/beam.yaml",
              "Config on the dwell points process_traces extracts from --traces");
DEFINE_string(traces_plan, "datasets/virtual-beam/plan.yaml",
              "Dwell plan the rig ran for --traces: its truth");
DEFINE_string(rig, "datasets/virtual-beam/rig.yaml", "Rig of --traces: channels, gauge, harmonics");
DEFINE_string(output, "docs/method-comparison.md", "Markdown file to write");
DEFINE_int32(noise_seeds, 5, "Noisy replicas of the numerical case");
DEFINE_double(phase_bias_deg, 2.0, "Phase error shown with the phase-lag fit [degrees]");
DEFINE_bool(wall_time, false, "Add wall-clock times (not reproducible) to the tables");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "method_comparison",
      "compares the chapter's identification methods and writes the tables as Markdown.\n"
      "  method_comparison [--numerical CFG --truth_plan PLAN --measured CFG --output FILE "
      "--traces DIR --traces_config CFG --traces_plan PLAN --rig RIG --noise_seeds N "
      "--phase_bias_deg D --wall_time]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    dwellfit::CheckOutputFile(FLAGS_output, "--output",
                              {FLAGS_numerical, FLAGS_truth_plan, FLAGS_measured,
                               FLAGS_traces_config, FLAGS_traces_plan, FLAGS_rig});
    dwellfit::MethodComparisonOptions options;
    options.noise_seeds = FLAGS_noise_seeds;
    options.phase_bias_deg = FLAGS_phase_bias_deg;
    options.wall_time = FLAGS_wall_time;
    std::string error;  // checked before the traces are read
    if (!options.IsValid(&error)) throw dwellfit::InputError("method comparison: " + error);
    std::optional<dwellfit::TraceCase> traces;
    if (!FLAGS_traces.empty()) {
      traces =
          dwellfit::LoadTraceCase(FLAGS_traces_config, FLAGS_traces_plan, FLAGS_rig, FLAGS_traces);
    }
    const std::string markdown = dwellfit::MethodComparisonMarkdown(
        dwellfit::LoadIdentifyConfig(FLAGS_numerical), dwellfit::ReadDwellPlan(FLAGS_truth_plan),
        dwellfit::LoadIdentifyConfig(FLAGS_measured), traces ? &*traces : nullptr, options);
    dwellfit::WriteReportAtomically(FLAGS_output, markdown);
    std::cout << "wrote " << FLAGS_output << "\n";
    return 0;
  });
}
