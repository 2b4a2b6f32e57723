// identify: identifies eta_e, mu1, mu2, delta, alpha and w from sine-dwell
// sweeps as a YAML config says (config/README.md), and writes result.yaml and
// predictions.csv. Flags override any config value for scripted studies.
#include <iostream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(config, "", "YAML config file (required), e.g. datasets/thesis-numerical/beam.yaml");
DEFINE_string(output_dir, "", "Overrides output_dir (relative to the working directory)");
DEFINE_string(fix, "",
              "Adds parameters to the config's fixed list: comma list, e.g. delta,omega (each "
              "needs an initial_guess)");
DEFINE_string(free, "", "Removes parameters from the config's fixed list: comma list, e.g. omega");
DEFINE_string(stages, "",
              "Overrides the fit stages: comma list of algebraic, vertical, phase_lag, all_roots");
DEFINE_string(residual_error, "", "Overrides residual.error: absolute or relative");
DEFINE_int32(max_iterations, 0, "Overrides solver.max_iterations when positive");
DEFINE_string(fit, "", "Overrides the fitted sweeps: comma list of ids or id/direction");
DEFINE_string(validate, "", "Overrides the validation sweeps: comma list");
DEFINE_bool(accept_no_convergence, false,
            "Exit 0 also when the fit stopped at its iteration limit (status no_convergence), "
            "for scripted studies that read result.yaml's status themselves");
DEFINE_bool(figures, true,
            "Render the figures (PNG and SVG) with gnuplot; without, curves.csv and the gnuplot "
            "script figures.gp are still written");
DEFINE_bool(mat, false,
            "Also write result.mat (MATLAB v5) beside result.yaml, as the config's outputs: {mat: "
            "true} does (docs/matlab.md)");
DEFINE_string(set, "",
              "Overrides any config value: key.path=value[,key.path=value...], each key once, "
              "e.g. initial_guess.mu1=0.3,solver.function_tolerance=1e-12");

namespace {

bool FlagGiven(const char* name) { return !gflags::GetCommandLineFlagInfoOrDie(name).is_default; }

std::vector<dwellfit::ConfigOverride> OverridesFromFlags() {
  using dwellfit::ConfigOverride;
  using dwellfit::ListFlagOverride;
  std::vector<ConfigOverride> overrides;
  if (FlagGiven("output_dir"))
    overrides.push_back({"output_dir", FLAGS_output_dir, "--output_dir"});
  if (FlagGiven("fix")) {
    overrides.push_back(
        ListFlagOverride("fixed", FLAGS_fix, "--fix", dwellfit::OverrideAction::kAddToList));
  }
  if (FlagGiven("free")) {
    overrides.push_back(
        ListFlagOverride("fixed", FLAGS_free, "--free", dwellfit::OverrideAction::kRemoveFromList));
  }
  if (FlagGiven("stages"))
    overrides.push_back(ListFlagOverride("stages", FLAGS_stages, "--stages"));
  if (FlagGiven("residual_error")) {
    overrides.push_back({"residual.error", FLAGS_residual_error, "--residual_error"});
  }
  if (FlagGiven("max_iterations")) {
    overrides.push_back(
        {"solver.max_iterations", std::to_string(FLAGS_max_iterations), "--max_iterations"});
  }
  if (FlagGiven("fit")) overrides.push_back(ListFlagOverride("fit", FLAGS_fit, "--fit"));
  if (FlagGiven("validate")) {
    overrides.push_back(ListFlagOverride("validate", FLAGS_validate, "--validate"));
  }
  for (ConfigOverride& o : dwellfit::ParseSetFlag(FLAGS_set, "--set")) overrides.push_back(o);
  return overrides;
}

}  // namespace

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "identify",
      "identifies a beam mode's parameters from sine-dwell sweeps.\n"
      "  identify --config beam.yaml [--output_dir DIR] [--fix delta,omega] [--set k=v,...]\n"
      "The config keys are documented in config/README.md.",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_config.empty()) {
      std::cerr << "identify: give the config file with --config FILE; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    const dwellfit::IdentifyConfig config =
        dwellfit::LoadIdentifyConfig(FLAGS_config, OverridesFromFlags());
    dwellfit::IdentifyRunOptions run_options;
    run_options.render_figures = FLAGS_figures;
    run_options.write_mat = FLAGS_mat;
    const auto outcome = dwellfit::RunIdentify(config, std::cout, run_options);
    const dwellfit::IdentificationResult& result = outcome->report.result;
    const int exit_status = dwellfit::ExitStatusFor(result.status, FLAGS_accept_no_convergence);
    if (result.status != dwellfit::FitStatus::kConverged) {
      std::cerr << "identify: status " << dwellfit::FitStatusName(result.status) << " (exit "
                << exit_status << "): " << result.message << "\n";
    }
    return exit_status;
  });
}
