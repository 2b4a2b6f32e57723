// Profile-likelihood intervals of the measured beam (the bar: at most 3 s on
// two cores for every free parameter and alpha_e, identify's whole run
// included, BM_ClampedBeamIdentifyRun below). RunProfile times the profiles
// alone, from the committed configs' fits (done once, outside the timing):
// EstimateUncertaintyAtMinimum with its solve again from the estimate, its
// profiles and any refit, on state.range(0) threads (0: the machine's).
#include <cstdlib>
#include <filesystem>
#include <ostream>
#include <streambuf>
#include <string>

#include "benchmark/benchmark.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {
namespace {

void RunProfile(benchmark::State& state, const std::string& config_name) {
  const IdentifyConfig config = LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) +
                                                   "/datasets/clamped-beam-27C/" + config_name);
  const ResolvedRun run = ResolveRun(config);
  const IdentificationResult fitted = FitRun(run).best;
  const double omega_ref = config.omega_ref_rad_s.value_or(fitted.parameters[kNaturalFrequency]);
  const int threads = ResolveThreadCount(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    IdentificationResult result = fitted;
    const ParameterUncertainty u =
        EstimateUncertaintyAtMinimum(run.fitted, run.options, omega_ref, &result, threads);
    state.counters["fits"] = u.profile.fits;
    state.counters["final_cost"] = result.final_cost;
    if (u.interval_kind != "profile_likelihood") state.SkipWithError(u.message.c_str());
  }
}

// On threads:1 and the default (0: the machine's), per committed config.
BENCHMARK_CAPTURE(RunProfile, ClampedBeamProfile, std::string("beam.yaml"))
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();
BENCHMARK_CAPTURE(RunProfile, ClampedBeamSelectedProfile, std::string("beam-selected.yaml"))
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

// The whole `identify` run on the committed clamped-beam config, in process
// (RunIdentify: reading the CSV, the fit, the profile intervals, the report,
// predictions.csv, curves.csv and figures.gp written into a temporary
// directory; no figures rendered, the printed report discarded), with
// solver.num_threads = state.range(0). Against BM_ClampedBeamFit at the same
// setting: what the run costs beyond its fit (process start-up aside).
// Here, beside the profiles alone, in a program of its own: a translation
// unit that includes much of the estimator slows every fit of its program
// (CMakeLists.txt, large-unit-insns).
void BM_ClampedBeamIdentifyRun(benchmark::State& state) {
  char directory_template[] = "/tmp/dwellfit-benchmark-XXXXXX";
  const char* directory = mkdtemp(directory_template);
  if (directory == nullptr) {
    state.SkipWithError("cannot create a temporary output directory");
    return;
  }
  const IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C/beam.yaml",
                         {{"output_dir", directory, "benchmark"},
                          {"solver.num_threads", std::to_string(state.range(0)), "benchmark"}});
  struct NullBuffer : std::streambuf {
    int overflow(int c) override { return c; }
  } null_buffer;
  std::ostream discard(&null_buffer);
  IdentifyRunOptions options;
  options.render_figures = false;
  for (auto _ : state) {
    const auto outcome = RunIdentify(config, discard, options);
    state.counters["iterations"] = outcome->report.result.iterations;
    state.counters["final_cost"] = outcome->report.result.final_cost;
  }
  std::error_code ignored;
  std::filesystem::remove_all(directory, ignored);
}
BENCHMARK(BM_ClampedBeamIdentifyRun)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
