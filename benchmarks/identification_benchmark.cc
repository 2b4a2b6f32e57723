// Speed of the thesis-numerical identification: the vertical residual with its
// Jacobian per dwell point, and the whole two-stage fit (about 260 points) on
// one core. Target: a whole fit under 20 ms.
#include <memory>
#include <string>
#include <vector>

#include "benchmark/benchmark.h"
#include "config/identify_config.h"
#include "estimator/identification.h"
#include "estimator/identify_run.h"
#include "estimator/problem_builder.h"

namespace dwellfit {
namespace {

const std::string kThesisConfig =
    std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml";

struct ThesisCase {
  IdentifyConfig config;
  std::vector<Sweep> sweeps;
  std::vector<const Sweep*> fitted;
};

const ThesisCase& Thesis() {
  static const ThesisCase* thesis = [] {
    auto* c = new ThesisCase;
    c->config = LoadIdentifyConfig(kThesisConfig);
    c->sweeps = LoadLabelledSweeps(c->config.data_files, c->config.jump_detection);
    c->fitted = SelectSweeps(c->sweeps, c->config.fit_sweeps, kThesisConfig, "fit");
    return c;
  }();
  return *thesis;
}

// Residual plus Jacobian of every fitted dwell, at the start; per point.
void BM_VerticalResidualWithJacobianPerPoint(benchmark::State& state) {
  const ThesisCase& thesis = Thesis();
  ProblemBuilder builder(ProblemBuilderOptions{});
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  for (const Sweep* sweep : thesis.fitted) {
    for (const DwellPoint& point : sweep->points) costs.emplace_back(builder.MakeResidual(point));
  }
  ParameterVector p = thesis.config.identification.initial;
  const double* blocks[] = {p.data()};
  double residual;
  double jacobian[kNumParameters];
  double* jacobians[] = {jacobian};
  for (auto _ : state) {
    for (const auto& cost : costs) {
      cost->Evaluate(blocks, &residual, jacobians);
      benchmark::DoNotOptimize(residual);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(costs.size()));
  state.counters["points"] = static_cast<double>(costs.size());
  state.counters["ns_per_point"] =
      benchmark::Counter(static_cast<double>(state.iterations() * costs.size()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_VerticalResidualWithJacobianPerPoint)->Unit(benchmark::kMicrosecond);

// The whole default fit (algebraic stage, then vertical) from the config's start.
void BM_ThesisNumericalWholeFit(benchmark::State& state) {
  const ThesisCase& thesis = Thesis();
  for (auto _ : state) {
    const IdentificationResult result = Identify(thesis.fitted, thesis.config.identification);
    benchmark::DoNotOptimize(result.parameters);
    state.counters["iterations"] = result.iterations;
    state.counters["converged"] = result.converged;
  }
}
BENCHMARK(BM_ThesisNumericalWholeFit)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
