// Profile-likelihood intervals of the measured beam (issue bar: at most 3 s
// on two cores for every free parameter and alpha_e, identify's whole run
// included: BM_ClampedBeamIdentifyRun in identification_benchmark.cc runs it
// with the profile). Here the profiles alone, from the committed configs'
// fits (done once, outside the timing): EstimateUncertaintyAtMinimum with
// its solve again from the estimate, its profiles and any refit, on
// state.range(0) threads (0: the machine's).
#include <string>

#include "benchmark/benchmark.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
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

void BM_ClampedBeamProfile(benchmark::State& state) { RunProfile(state, "beam.yaml"); }
BENCHMARK(BM_ClampedBeamProfile)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

void BM_ClampedBeamSelectedProfile(benchmark::State& state) {
  RunProfile(state, "beam-selected.yaml");
}
BENCHMARK(BM_ClampedBeamSelectedProfile)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
