// Runs a dwell plan on the virtual sine-dwell rig and writes the time traces.
//
//   simulate_rig --plan datasets/virtual-beam/plan.yaml \
//                --rig datasets/virtual-beam/rig.yaml --out datasets/virtual-beam/traces
//
// The plan (config/dwell_plan_reader.h) gives the truth and the sweeps, the
// rig (config/rig_config_reader.h) the sampling, channels, noise and gauge.
// Writes <out>/traces.csv, <out>/traces.f32 (estimator/traces/trace_file.h)
// and <out>/truth.csv (estimator/rig/rig_simulator.h). A progress bar is drawn
// when stderr is a terminal. Exits 1 on bad input, 3 when a dwell did not
// settle (the traces are written, the truth marks it).
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/rig_config_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/rig/rig_simulator.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(plan, "", "YAML dwell plan: truth parameters and sweeps (required).");
DEFINE_string(rig, "", "YAML rig: sampling, channels, noise, beam and gauge (required).");
DEFINE_string(out, "", "Folder for traces.csv, traces.f32 and truth.csv (required).");

namespace {

void DrawProgress(int done, int total) {
  const int width = 40;
  const int filled = total > 0 ? width * done / total : width;
  std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ') << "] " << done
            << "/" << total << " dwells" << (done == total ? "\n" : "") << std::flush;
}

}  // namespace

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "simulate_rig",
      "Simulates a sine-dwell test on the virtual rig and writes time traces.\n"
      "Usage: simulate_rig --plan plan.yaml --rig rig.yaml --out traces_folder",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_plan.empty() || FLAGS_rig.empty() || FLAGS_out.empty()) {
      std::cerr << "simulate_rig: give --plan, --rig and --out; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    const dwellfit::DwellPlan plan = dwellfit::ReadDwellPlan(FLAGS_plan);
    const dwellfit::RigConfig rig = dwellfit::ReadRigConfig(FLAGS_rig);
    const auto start = std::chrono::steady_clock::now();
    const dwellfit::RigRun run = dwellfit::SimulateRig(
        plan, rig.rig, isatty(STDERR_FILENO) ? dwellfit::RigProgress(DrawProgress) : nullptr);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // The trace index is written last: a run stopped before it leaves a set
    // whose index and samples disagree, which process_traces refuses
    // (samples_crc32, estimator/traces/trace_file.h).
    std::error_code error;
    std::filesystem::create_directories(FLAGS_out, error);
    dwellfit::WriteRigTruthCsv(run, (std::filesystem::path(FLAGS_out) / "truth.csv").string());
    dwellfit::WriteTraceSet(run.traces, FLAGS_out);
    int unsettled = 0;
    for (const auto& truth : run.dwell_truth) unsettled += truth.settled ? 0 : 1;
    std::cout << dwellfit::StringPrintf(
        "simulated %zu dwells in %.1f s (%.1f dwells/s); %d did "
        "not settle\nwrote %s\n",
        run.traces.size(), seconds, run.traces.size() / seconds, unsettled, FLAGS_out.c_str());
    return unsettled > 0 ? 3 : 0;
  });
}
