// Simulates a stepped sine-dwell test on the model and writes the sweeps CSV.
//
//   simulate_dwell --plan datasets/thesis-numerical/plan.yaml \
//                  --out datasets/thesis-numerical/sweeps.csv
//
// The plan (config/dwell_plan_reader.h) gives the true parameters, the
// sweeps and the noise; the plan in effect and each sweep's jumps are printed.
#include <iostream>
#include <sstream>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(plan, "", "YAML dwell plan: truth parameters, sweeps, noise (required).");
DEFINE_string(out, "", "CSV file to write (sweep,direction,freq_hz,a_base,a) (required).");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {"simulate_dwell",
                                   "Simulates sine-dwell sweeps on the model from a plan.\n"
                                   "Usage: simulate_dwell --plan plan.yaml --out sweeps.csv",
                                   __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_plan.empty() || FLAGS_out.empty()) {
      std::cerr << "simulate_dwell: give both --plan and --out; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    dwellfit::CheckOutputFile(FLAGS_out, "--out", {FLAGS_plan});
    const dwellfit::DwellPlan plan = dwellfit::ReadDwellPlan(FLAGS_plan);
    const std::vector<dwellfit::Sweep> sweeps = dwellfit::SimulateDwells(plan);
    std::ostringstream csv;
    dwellfit::WriteSweepsCsv(sweeps, &csv);
    dwellfit::WriteReportAtomically(FLAGS_out, csv.str(), "--out");  // never half-written
    dwellfit::DescribeSimulation(plan, sweeps, &std::cout);
    std::cout << "wrote " << FLAGS_out << "\n";
    return 0;
  });
}
