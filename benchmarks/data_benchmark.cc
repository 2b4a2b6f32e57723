// Reading the bundled sweeps: LoadSweepsCsv on the clamped beam's 24,576 rows
// (twelve sweeps, up and down), the first step of every identify run on it.
#include <cstdint>
#include <string>

#include "benchmark/benchmark.h"
#include "dwellfit/estimator/data/sweep_csv.h"

namespace dwellfit {
namespace {

void BM_LoadClampedBeamSweepsCsv(benchmark::State& state) {
  const std::string path =
      std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C/sweeps.csv";
  std::size_t rows = 0;
  for (auto _ : state) {
    const LoadedSweeps loaded = LoadSweepsCsv(path);
    rows = 0;
    for (const Sweep& sweep : loaded.sweeps) rows += sweep.points.size() + sweep.missing.size();
    benchmark::DoNotOptimize(rows);
  }
  state.counters["rows"] = static_cast<double>(rows);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * rows));
}
BENCHMARK(BM_LoadClampedBeamSweepsCsv)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
