// design_study: the closed loop (fit -> next_dwell -> one dwell -> refit) on
// the virtual rig beside the standard protocol (the plan's uniform sweeps),
// over noise seeds: the simulated test time each needs to reach a precision
// target, the dwells, and whether the final intervals cover the truth
// (estimator/design/design_study.h, docs/design-study.md).
#include <cstdio>
#include <iostream>
#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/design/design_study.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"

DEFINE_string(name, "case", "the case's name in the table and files");
DEFINE_string(config, "", "identify config YAML: initial guess, residual, Omega_ref (required)");
DEFINE_string(plan, "", "dwell plan YAML: the truth and the standard sweeps (required)");
DEFINE_string(rig, "", "rig config YAML: sampling, settling, channels, noise, gauge (required)");
DEFINE_int32(seeds, 10, "noise seeds per arm");
DEFINE_uint64(first_seed, 1, "the first noise seed; the others follow");
DEFINE_double(budget_s, 7200, "simulated test time per arm and seed [s]");
DEFINE_int32(refit_dwells, 0,
             "standard protocol: refit every k dwells too (0: after each sweep direction)");
DEFINE_int32(start_step_factor, 5, "closed loop: the start sweeps' step in plan steps");
DEFINE_double(f_step_max_hz, 0.0,
              "closed loop: largest frequency step between dwells [Hz] (0: the plan's span)");
DEFINE_double(level_step_max, 0.0,
              "closed loop: largest base-level step between dwells (0: the plan's span)");
DEFINE_int32(hysteresis_steps, 2,
             "closed loop: dwells in the hysteresis range only within this many smallest steps");
DEFINE_double(settle_time_constants, 5.0, "next_dwell's settling cost model k");
DEFINE_string(target, "0.01,0.005,0.0005,0.10",
              "bounds on the 95 % half-width relative to the estimate: alpha_e,eta_e,w,mu1");
DEFINE_bool(simultaneous, true,
            "judge the target and the coverage on simultaneous 95 % intervals of the four "
            "quantities (each at 0.95^(1/4)); false: each quantity's own 95 % interval");
DEFINE_string(output_dir, ".", "folder for design_study.csv, design_study_fits.csv, the figure");
DEFINE_bool(figures, true, "render the figure with gnuplot");
DEFINE_string(averaging, "config",
              "the fits' model: config (the config's model key), first_order or second_order");

namespace {

dwellfit::DesignStudyOptions OptionsFromFlags() {
  dwellfit::DesignStudyOptions options;
  options.seeds = FLAGS_seeds;
  options.first_seed = FLAGS_first_seed;
  options.time_budget_seconds = FLAGS_budget_s;
  options.refit_dwells = FLAGS_refit_dwells;
  options.start_step_factor = FLAGS_start_step_factor;
  options.frequency_step_max_hz = FLAGS_f_step_max_hz;
  options.level_step_max = FLAGS_level_step_max;
  options.settle_time_constants = FLAGS_settle_time_constants;
  options.hysteresis_steps = FLAGS_hysteresis_steps;
  options.target.simultaneous = FLAGS_simultaneous;
  const std::string& t = FLAGS_target;
  double* b = options.target.relative_half_width.data();
  char tail = 0;
  if (std::sscanf(t.c_str(), "%lf,%lf,%lf,%lf%c", b, b + 1, b + 2, b + 3, &tail) != 4) {
    throw dwellfit::InputError("--target", 0, t,
                               "give four relative bounds alpha_e,eta_e,w,mu1, e.g. "
                               "0.01,0.005,0.0005,0.1");
  }
  if (FLAGS_averaging != "config") {
    dwellfit::Averaging averaging;
    if (!dwellfit::AveragingFromName(FLAGS_averaging, &averaging)) {
      throw dwellfit::InputError("--averaging", 0, FLAGS_averaging,
                                 "give config, first_order or second_order");
    }
    options.averaging = averaging;
  }
  std::string error;
  if (!options.IsValid(&error)) throw dwellfit::InputError("design_study flags", 0, "", error);
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "design_study",
      "runs the closed loop (fit, next_dwell, dwell, refit) and the standard protocol on the\n"
      "virtual rig over seeds and reports the simulated test time to a precision target.\n"
      "  design_study --config beam.yaml --plan plan.yaml --rig rig.yaml [--seeds 10]\n"
      "See docs/design-study.md.",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_config.empty() || FLAGS_plan.empty() || FLAGS_rig.empty()) {
      std::cerr << "design_study: give --config, --plan and --rig; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    const dwellfit::DesignStudyOptions options = OptionsFromFlags();
    dwellfit::CheckOutputDirectory(FLAGS_output_dir, "--output_dir");
    const dwellfit::DesignStudyCase study =
        dwellfit::LoadDesignStudyCase(FLAGS_name, FLAGS_config, FLAGS_plan, FLAGS_rig);
    const dwellfit::DesignStudyResult result = dwellfit::RunDesignStudy(study, options, &std::cerr);
    dwellfit::PrintDesignStudy(result, options, std::cout);
    std::string warning;
    dwellfit::WriteFilesAtomically(
        FLAGS_output_dir, dwellfit::DesignStudyFiles({result}, options, FLAGS_figures, &warning));
    if (!warning.empty()) std::cout << "figures: " << warning << "\n";
    std::cout << "wrote " << FLAGS_output_dir << "/" << dwellfit::kDesignStudyCsvName << "\n";
    return 0;
  });
}
