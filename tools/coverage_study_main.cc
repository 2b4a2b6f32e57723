// Checks the 95 % intervals of the parameter uncertainty by simulation.
//
//   coverage_study --config datasets/thesis-numerical/beam.yaml \
//                  --plan datasets/thesis-numerical/plan.yaml --replicas 200 --noise 0.01 \
//                  [--set 'initial_guess=auto,fixed=[]'] [--interval_method data_only]
//
// Fits `replicas` noisy simulations of the plan with the config (each taking
// the path of a measured run: labelled, the config's jumps applied, the
// start found from its data where the config leaves it out) and prints,
// per free parameter and for the effective nonlinearity, how often the 95 %
// interval covers the truth (estimator/studies/coverage_study.h).
#include <iostream>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/studies/coverage_study.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(config, "",
              "identify config YAML: start, fixed parameters, fitted sweeps (required).");
DEFINE_string(plan, "", "YAML dwell plan: truth and sweeps to simulate (required).");
DEFINE_int32(replicas, 200, "number of noisy replicas.");
DEFINE_double(noise, 0.01, "relative noise sigma: a *= 1 + noise N(0, 1).");
DEFINE_uint64(first_seed, 1, "seed of the first replica; replica r uses first_seed + r.");
DEFINE_string(interval_method, "profile",
              "which intervals: profile (identify's: profile likelihood of the fitted cost), "
              "linearised (with the penalty's curvature) or data_only (the dwells' "
              "linearisation alone).");
DEFINE_string(set, "",
              "Overrides config values as identify's --set does: key.path=value[,...], e.g. "
              "'initial_guess=auto,fixed=[]'");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "coverage_study",
      "Coverage of the 95 % parameter intervals over noisy simulated replicas.\n"
      "Usage: coverage_study --config beam.yaml --plan plan.yaml [--replicas 200] "
      "[--noise 0.01] [--set key.path=value,...]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_config.empty() || FLAGS_plan.empty() || FLAGS_replicas < 1 || !(FLAGS_noise >= 0.0)) {
      std::cerr << "coverage_study: give --config and --plan, --replicas >= 1, --noise >= 0; see "
                   "--help\n";
      return dwellfit::kToolExitUsage;
    }
    const dwellfit::IdentifyConfig config =
        dwellfit::LoadIdentifyConfig(FLAGS_config, dwellfit::ParseSetFlag(FLAGS_set, "--set"));
    const dwellfit::DwellPlan plan = dwellfit::ReadDwellPlan(FLAGS_plan);
    dwellfit::CoverageStudyOptions options;
    options.replicas = FLAGS_replicas;
    options.relative_noise = FLAGS_noise;
    options.first_seed = FLAGS_first_seed;
    if (!dwellfit::ParseIntervalMethod(FLAGS_interval_method, &options.method)) {
      std::cerr << "coverage_study: --interval_method '" << FLAGS_interval_method
                << "': give profile, linearised or data_only\n";
      return dwellfit::kToolExitUsage;
    }
    dwellfit::PrintCoverageStudy(dwellfit::RunCoverageStudy(config, plan, options), std::cout);
    return 0;
  });
}
