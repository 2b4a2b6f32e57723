// Speed of the virtual rig: dwells simulated per second (items/s) on the
// chapter's frequency sweep F0.01 (38-46 Hz in 0.1 Hz steps, up and down,
// 162 dwells, Table 3.1 truth), with the rig of datasets/virtual-beam
// (2048 Hz, 16 recorded periods, settling to 1e-4 over 50-period windows).
#include <benchmark/benchmark.h>

#include <string>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/rig_config_reader.h"
#include "dwellfit/estimator/rig/rig_simulator.h"

namespace dwellfit {
namespace {

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/virtual-beam";

void BM_SimulateFrequencySweep(benchmark::State& state) {
  DwellPlan plan = ReadDwellPlan(kDataset + "/plan.yaml");
  plan.sweeps.resize(1);  // F0.01, up and down
  const RigConfig rig = ReadRigConfig(kDataset + "/rig.yaml");
  std::size_t dwells = 0;
  for (auto _ : state) {
    const RigRun run = SimulateRig(plan, rig.rig);
    dwells += run.traces.size();
    benchmark::DoNotOptimize(run.traces.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(dwells));
}
BENCHMARK(BM_SimulateFrequencySweep)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
