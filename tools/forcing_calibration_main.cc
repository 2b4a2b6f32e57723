// forcing_calibration: held-out errors of a config's validation sweeps with
// and without the per-sweep forcing calibration (estimator/fit/
// forcing_calibration.h), as Markdown on stdout or into --output.
#include <iostream>
#include <string>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/studies/forcing_calibration_study.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"

DEFINE_string(config, "", "Identify config whose validation sweeps are predicted");
DEFINE_double(prior_sigma, 0.05,
              "Standard deviation of each sweep's forcing scale around 1 (overrides the config's "
              "forcing_calibration.prior_sigma)");
DEFINE_string(
    held_out_dwells, "before_jump",
    "A held-out sweep's dwells its scale is calibrated on: before_jump (up to its first "
    "jump) or below_half_peak (of those, below half their largest amplitude); overrides the "
    "config's");
DEFINE_string(parameter, "eta_e",
              "The parameter each sweep gets of its own: eta_e (its forcing) or omega (its "
              "natural frequency); overrides the config's");
DEFINE_string(set, "",
              "Overrides config values as identify's --set: key.path=value[,...], e.g. "
              "\"fixed=[mu2, delta],initial_guess.delta=0\"");
DEFINE_string(output, "", "Markdown file to write (empty: stdout)");
DEFINE_bool(leave_one_level_out, false,
            "Hold out each fitted and validated level in turn, fitting all the others");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "forcing_calibration",
      "held-out errors with and without per-sweep forcing calibration.\n"
      "  forcing_calibration --config CFG [--set K=V --prior_sigma S --held_out_dwells before_jump|"
      "below_half_peak --parameter eta_e|omega --leave_one_level_out --output FILE]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (!FLAGS_output.empty()) dwellfit::CheckOutputFile(FLAGS_output, "--output", {FLAGS_config});
    const dwellfit::IdentifyConfig config =
        dwellfit::LoadIdentifyConfig(FLAGS_config, dwellfit::ParseSetFlag(FLAGS_set, "--set"));
    // The config's block, then the flags given.
    dwellfit::ForcingCalibrationOptions calibration =
        config.forcing_calibration.value_or(dwellfit::ForcingCalibrationOptions());
    if (!gflags::GetCommandLineFlagInfoOrDie("prior_sigma").is_default) {
      calibration.prior_sigma = FLAGS_prior_sigma;
    }
    if (!gflags::GetCommandLineFlagInfoOrDie("held_out_dwells").is_default &&
        !dwellfit::HeldOutDwellsFromName(FLAGS_held_out_dwells, &calibration.held_out_dwells)) {
      throw dwellfit::InputError(
          "--held_out_dwells", 0, "",
          "give before_jump or below_half_peak, got '" + FLAGS_held_out_dwells + "'");
    }
    if (!gflags::GetCommandLineFlagInfoOrDie("parameter").is_default &&
        !dwellfit::CalibratedParameterFromName(FLAGS_parameter, &calibration.parameter)) {
      throw dwellfit::InputError("--parameter", 0, "",
                                 "give eta_e or omega, got '" + FLAGS_parameter + "'");
    }
    const std::string markdown =
        FLAGS_leave_one_level_out
            ? dwellfit::LeaveOneLevelOutMarkdown(config, calibration,
                                                 dwellfit::LeaveOneLevelOut(config, calibration))
            : dwellfit::ForcingCalibrationMarkdown(
                  dwellfit::CompareForcingCalibration(config, calibration));
    if (FLAGS_output.empty()) {
      std::cout << markdown;
    } else {
      dwellfit::WriteReportAtomically(FLAGS_output, markdown);
      std::cout << "wrote " << FLAGS_output << "\n";
    }
    return 0;
  });
}
