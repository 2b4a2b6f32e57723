// The model's whole response curves (every branch with its stability, the
// folds, the backbone) as CSV (estimator/curves/sweep_curves.h, docs/outputs.md).
//
//   curves --result out/thesis-numerical/result.yaml --kind frequency --a_base 0.01 \
//          --from 38 --to 46 > F0.01.csv
//   curves --plan datasets/thesis-numerical/plan.yaml --output curves.csv
//   curves --plan plan.yaml --mu2 250 --kind amplitude --freq_hz 41.5 --from 0.002 --to 0.05
//
// Parameters: --result (an identify result.yaml) or --plan (a dwell plan's
// truth), then any of --eta_e --mu1 --mu2 --delta --alpha --omega_hz. Curves:
// --kind with --a_base or --freq_hz and --from/--to (Hz or a_base), else the
// plan's sweeps.
#include <cmath>
#include <iostream>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/result_parameters.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/curves/sweep_curves.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(result, "", "identify's result.yaml to take the parameters from.");
DEFINE_string(plan, "", "dwell plan YAML: its truth (parameters) and, without --kind, its sweeps.");
DEFINE_double(eta_e, NAN, "forcing effectiveness eta_e (overrides --result/--plan).");
DEFINE_double(mu1, NAN, "linear damping mu1 [1/s].");
DEFINE_double(mu2, NAN, "quadratic damping mu2 [1/(amplitude unit s)].");
DEFINE_double(delta, NAN, "nonlinear inertia delta [1/amplitude unit^2].");
DEFINE_double(alpha, NAN, "cubic stiffness alpha [1/(amplitude unit^2 s^2)].");
DEFINE_double(omega_hz, NAN, "linear natural frequency [Hz].");
DEFINE_string(kind, "", "frequency or amplitude: one curve from the flags below.");
DEFINE_double(a_base, NAN, "frequency curve: the held base level.");
DEFINE_double(freq_hz, NAN, "amplitude curve: the held drive frequency [Hz].");
DEFINE_double(from, NAN, "start of the swept range: Hz (frequency) or a_base (amplitude).");
DEFINE_double(to, NAN, "end of the swept range.");
DEFINE_int32(points, 400, "samples per side of each curve (folds are added exactly).");
DEFINE_string(id, "curve", "the sweep column's value for a curve given by flags.");
DEFINE_string(output, "", "CSV file to write (default: standard output).");
DEFINE_string(averaging, "",
              "the response model: first_order or second_order (default: the plan's model, "
              "else first_order).");

namespace {

dwellfit::ParameterVector Parameters(const dwellfit::DwellPlan* plan) {
  using namespace dwellfit;
  ParameterVector p{};
  bool have = false;
  if (!FLAGS_result.empty()) {
    p = ReadResultParameters(FLAGS_result);
    have = true;
  } else if (plan != nullptr) {
    p = plan->truth;
    have = true;
  }
  const double flags[kNumParameters] = {FLAGS_eta_e, FLAGS_mu1,   FLAGS_mu2,
                                        FLAGS_delta, FLAGS_alpha, FLAGS_omega_hz};
  for (int i = 0; i < kNumParameters; ++i) {
    if (std::isnan(flags[i])) {
      if (!have) {
        throw InputError("--" + std::string(i == kNaturalFrequency ? "omega_hz" : ParameterName(i)),
                         0, "", "not given; give --result, --plan or every parameter flag");
      }
      continue;
    }
    p[i] = i == kNaturalFrequency ? HzToRadPerSecond(flags[i]) : flags[i];
  }
  return p;
}

std::vector<dwellfit::CurveSpec> Specs(const dwellfit::DwellPlan* plan) {
  using namespace dwellfit;
  std::vector<CurveSpec> specs;
  if (FLAGS_kind.empty()) {
    if (plan == nullptr) throw InputError("--kind", 0, "", "give --kind (or --plan with sweeps)");
    for (const SweepPlan& sweep : plan->sweeps) {
      CurveSpec spec;
      spec.name = sweep.id;
      spec.kind = sweep.kind;
      const bool frequency = sweep.kind == SweepKind::kFrequency;
      spec.a_base = sweep.held_a_base;
      spec.omega_rad_s = HzToRadPerSecond(sweep.held_frequency_hz);
      spec.control_low = frequency ? HzToRadPerSecond(sweep.from) : sweep.from;
      spec.control_high = frequency ? HzToRadPerSecond(sweep.to) : sweep.to;
      specs.push_back(spec);
    }
  } else {
    CurveSpec spec;
    spec.name = FLAGS_id;
    if (FLAGS_kind != "frequency" && FLAGS_kind != "amplitude")
      throw InputError("--kind", 0, "", "'" + FLAGS_kind + "' is not frequency or amplitude");
    spec.kind = FLAGS_kind == "frequency" ? SweepKind::kFrequency : SweepKind::kAmplitude;
    const bool frequency = spec.kind == SweepKind::kFrequency;
    spec.a_base = FLAGS_a_base;
    spec.omega_rad_s = HzToRadPerSecond(FLAGS_freq_hz);
    spec.control_low = frequency ? HzToRadPerSecond(FLAGS_from) : FLAGS_from;
    spec.control_high = frequency ? HzToRadPerSecond(FLAGS_to) : FLAGS_to;
    specs.push_back(spec);
  }
  for (CurveSpec& spec : specs) {
    spec.points_per_side = FLAGS_points;
    std::string why;
    if (!spec.IsValid(&why)) throw InputError("--kind/--a_base/--freq_hz/--from/--to", 0, "", why);
  }
  return specs;
}

}  // namespace

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "curves",
      "The model's response curves as CSV.\nUsage: curves (--result result.yaml | --plan "
      "plan.yaml | --eta_e .. --omega_hz ..) [--kind frequency --a_base A --from HZ --to HZ | "
      "--kind amplitude --freq_hz HZ --from A --to A] [--output curves.csv]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (!FLAGS_output.empty()) {
      dwellfit::CheckOutputFile(FLAGS_output, "--output", {FLAGS_result, FLAGS_plan});
    }
    std::optional<dwellfit::DwellPlan> plan;
    if (!FLAGS_plan.empty()) plan = dwellfit::ReadDwellPlan(FLAGS_plan);
    const dwellfit::DwellPlan* plan_ptr = plan ? &*plan : nullptr;
    dwellfit::ModelForm form = plan ? plan->form : dwellfit::ModelForm();
    if (!FLAGS_averaging.empty() &&
        !dwellfit::AveragingFromName(FLAGS_averaging, &form.averaging)) {
      throw dwellfit::InputError(
          "--averaging", 0, "",
          "unknown averaging '" + FLAGS_averaging + "'; allowed: first_order, second_order");
    }
    const std::vector<dwellfit::ResponseCurve> curves =
        dwellfit::TraceCurves(form, Parameters(plan_ptr), Specs(plan_ptr));
    for (const dwellfit::ResponseCurve& curve : curves) {
      // Parameters or a range far outside a structure's (1e300, 1e-300)
      // leave no finite response to trace: an error, not an empty file.
      if (curve.points.size() < 2) {
        throw dwellfit::InputError(
            "curve '" + curve.spec.name + "'", 0, "",
            "the model has no finite response over the range for these parameters; check their "
            "values and units and the range (--from, --to, --a_base, --freq_hz)");
      }
    }
    const std::string csv = dwellfit::CurvesToCsv(curves);
    if (FLAGS_output.empty()) {
      std::cout << csv;
    } else {
      dwellfit::WriteReportAtomically(FLAGS_output, csv);  // never a half-written file
    }
    return 0;
  });
}
