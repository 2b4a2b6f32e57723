// Speed of one next-dwell recommendation on the thesis case
// (datasets/thesis-numerical, docs/next-dwell.md), on one core; the target is
// at most 100 ms. `Rank`: the ranking alone from a finished fit's basis, over
// the grid of the fitted sweeps' own span and spacing (81 frequencies x 49
// levels, 3968 candidates); `Whole`: what the tool does, config to ranking
// (load, fit, covariance, ranking, next_dwell.csv text; no figure).
#include <sstream>
#include <string>

#include "benchmark/benchmark.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/design/next_dwell.h"
#include "dwellfit/estimator/design/next_dwell_run.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {
namespace {

// The allocator policy every dwellfit tool sets first (memory_policy.h).
const bool kToolAllocatorPolicy = KeepFreedMemoryForReuse();

IdentifyConfig ThesisConfig() {
  IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml");
  config.identification.solve.solver.num_threads = 1;  // one core
  return config;
}

NextDwellRequest Request() {
  NextDwellRequest request;
  request.state = {41.5, 0.01, Branch::kUpper};
  request.options.noise_sigma = 0.01;
  request.render_figures = false;
  return request;
}

void BM_NextDwellRank(benchmark::State& state) {
  const IdentifyConfig config = ThesisConfig();
  const ResolvedRun run = ResolveRun(config);
  const IdentificationResult fit = FitRun(run).best;
  DesignBasis basis;
  std::string why;
  if (!DesignBasisFromFit(run.fitted, run.options, fit.parameters,
                          config.omega_ref_rad_s.value_or(0.0), &basis, &why)) {
    state.SkipWithError(why.c_str());
    return;
  }
  const RigLimits limits = LimitsFromSweeps(run.fitted);
  const NextDwellRequest request = Request();
  std::size_t candidates = 0;
  for (auto _ : state) {
    const Recommendation rec = RecommendNextDwell(basis, request.state, limits, request.options);
    candidates = rec.ranked.size();
    benchmark::DoNotOptimize(rec.ranked.front().gain);
  }
  state.counters["candidates"] = static_cast<double>(candidates);
}
BENCHMARK(BM_NextDwellRank)->Unit(benchmark::kMillisecond);

void BM_NextDwellWhole(benchmark::State& state) {
  const IdentifyConfig config = ThesisConfig();
  const NextDwellRequest request = Request();
  for (auto _ : state) {
    std::ostringstream out;
    const NextDwellOutcome outcome = ComputeNextDwell(config, request, out);
    benchmark::DoNotOptimize(outcome.files.front().second.size());
  }
}
BENCHMARK(BM_NextDwellWhole)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
