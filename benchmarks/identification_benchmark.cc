// Speed of the identification: the vertical residual with its Jacobian per
// dwell point, the whole two-stage thesis-numerical fit (about 260 points;
// target under 20 ms), and the measured clamped-beam fit (two levels, 4096
// dwells, with the bifurcation-range penalty; target under 200 ms). The fits
// run with the residual blocks evaluated on 1 and on 2 threads (the argument);
// their results do not depend on it.
#include <memory>
#include <string>
#include <vector>

#include "benchmark/benchmark.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {
namespace {

// A committed dataset config, resolved once (data labelled and selected,
// start found) as `identify` resolves it.
ResolvedRun* LoadCase(const std::string& dataset) {
  return new ResolvedRun(ResolveRun(LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) +
                                                       "/datasets/" + dataset + "/beam.yaml")));
}

ResolvedRun& Thesis() {
  static ResolvedRun* thesis = LoadCase("thesis-numerical");
  return *thesis;
}

ResolvedRun& ClampedBeam() {
  static ResolvedRun* beam = LoadCase("clamped-beam-27C");
  return *beam;
}

// The configured fit of `run` (FitRun, as `identify` fits), with its residual
// blocks evaluated on state.range(0) threads.
void RunConfiguredFit(benchmark::State& state, ResolvedRun& run) {
  run.options.solver.num_threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const IdentificationResult result = FitRun(run).best;
    benchmark::DoNotOptimize(result.parameters);
    state.counters["iterations"] = result.iterations;
    state.counters["dwells"] = result.residual_blocks;
    state.counters["final_cost"] = result.final_cost;
    state.counters["converged"] = result.converged;
  }
}

// Residual plus Jacobian of every fitted dwell, per point, alternating between
// the start and a point 0.1 % away in every parameter, as a solver's steps
// do (each dwell's Newton iteration starts from its root at the last point).
void BM_VerticalResidualWithJacobianPerPoint(benchmark::State& state) {
  const ResolvedRun& thesis = Thesis();
  ProblemBuilder builder(ProblemBuilderOptions{});
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  for (const Sweep* sweep : thesis.fitted) {
    for (const DwellPoint& point : sweep->points) costs.emplace_back(builder.MakeResidual(point));
  }
  const ParameterVector start = thesis.options.initial;
  ParameterVector moved = start;
  for (double& value : moved) value *= 1.001;
  const double* at_start[] = {start.data()};
  const double* at_moved[] = {moved.data()};
  double residual;
  double jacobian[kNumParameters];
  double* jacobians[] = {jacobian};
  bool moved_now = false;
  for (auto _ : state) {
    const double* const* blocks = moved_now ? at_moved : at_start;
    moved_now = !moved_now;
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
void BM_ThesisNumericalWholeFit(benchmark::State& state) { RunConfiguredFit(state, Thesis()); }
BENCHMARK(BM_ThesisNumericalWholeFit)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The committed clamped-beam config: algebraic stage, then the vertical error
// with the bifurcation-range penalty (exponent 2, then 10), from its start.
// Wall time is what counts here (UseRealTime): the evaluation runs on threads.
void BM_ClampedBeamFit(benchmark::State& state) { RunConfiguredFit(state, ClampedBeam()); }
BENCHMARK(BM_ClampedBeamFit)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
