// Speed of a sensitivity study: the noise study of thesis-numerical,
//   sensitivity --config beam.yaml --plan plan.yaml --replicas 1000 --noise 0.01 --threads 2
// (1000 fits, each with its standard errors; target under 5 s on two
// cores), and the same study's fits without standard errors. The argument
// is the thread count; fits.csv does not depend on it.
#include <string>

#include "benchmark/benchmark.h"
#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/studies/sensitivity_study.h"

namespace dwellfit {
namespace {

const std::string kThesis = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/";

void BM_NoiseStudyThesis1000(benchmark::State& state, bool standard_errors) {
  SensitivityOptions options;
  options.config_path = kThesis + "beam.yaml";
  options.plan = ReadDwellPlan(kThesis + "plan.yaml");
  options.replicas = 1000;
  options.noise = 0.01;
  options.threads = static_cast<int>(state.range(0));
  options.standard_errors = standard_errors;
  int usable = 0;
  for (auto _ : state) {
    const SensitivityStudy study = RunSensitivityStudy(options);
    usable = 0;
    for (const FitRow& row : study.rows) usable += row.status == "converged";
    benchmark::DoNotOptimize(usable);
  }
  state.counters["converged_fits"] = usable;
}

BENCHMARK_CAPTURE(BM_NoiseStudyThesis1000, with_standard_errors, true)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_NoiseStudyThesis1000, estimates_only, false)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
