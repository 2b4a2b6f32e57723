// Speed of model selection over the measured beam's twelve levels
// (datasets/clamped-beam-27C/beam-selected.yaml: delta free or 0, each
// variant fitted on the config's two levels and on the two stand-in training
// sets of leave-one-level-out, six starts per fit: 36 fits of 4096 dwells).
// Target: under 10 s on two cores (the argument: fits at once). The report
// does not depend on the thread count.
#include <string>

#include "benchmark/benchmark.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/studies/model_selection.h"

namespace dwellfit {
namespace {

void BM_ModelSelectionClampedBeam(benchmark::State& state) {
  const IdentifyConfig config = LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) +
                                                   "/datasets/clamped-beam-27C/beam-selected.yaml");
  for (auto _ : state) {
    const ModelSelectionReport report = RunModelSelection(config, static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(report.recommended);
    int fits = 0;
    for (const VariantResult& v : report.variants) fits += static_cast<int>(v.fits.size());
    state.counters["fits"] = fits;
    state.counters["recommended"] = report.recommended;
    state.counters["cv_jump_down_median_pct"] =
        MedianOf(report.variants[report.recommended < 0 ? 0 : report.recommended]
                     .cross_validation.jump_down_percent);
  }
}
BENCHMARK(BM_ModelSelectionClampedBeam)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
