// Growth of the fit with the number of dwells: wall time and peak memory of
// the identification of one simulated frequency sweep (up and down) of N
// dwells, N = 1e3 to 1e6, on 1 and 2 threads (docs/performance.md).
//
// The sweep is the thesis-numerical model (datasets/thesis-numerical/plan.yaml:
// eta_e 100, mu1 0.2, mu2 300, delta 1e4, alpha 9e8, w = 2 pi 40 rad/s) driven
// at a_base = 0.01 from 38 Hz to 46 Hz and back, N / 2 dwells each way, with
// 1 % multiplicative noise (seed 1), simulated by SimulateDwells; its branch
// labels are the simulator's. It is fitted as `identify` fits: Identify (the
// algebraic stage, then the vertical error in ln a) from the thesis config's
// start (30 % off, w known), then EstimateUncertainty at the estimate (the
// covariance `identify` reports).
//
// Counters: fit_s and covariance_s (wall time of each); fit_peak_MB and
// covariance_peak_MB (the process's peak resident memory during each, above
// its resident memory just before, which holds the simulated sweep:
// malloc_trim returns freed heap pages first, /proc/self/clear_refs resets
// the peak, /proc/self/status VmHWM reads it); peak_MB (the larger) and
// bytes_per_dwell (peak_MB over N); iterations, final_cost, converged, and
// max_rel_error (the largest relative distance of a free parameter from the
// truth: the noise's, shrinking like 1/sqrt(N)).
//
// Every case runs once (Iterations(1)); the million-dwell cases are their
// own benchmark, so that
//   build/benchmarks/growth_benchmark --benchmark_filter='BM_GrowthFit/'
// runs N = 1e3..1e5 and --benchmark_filter=Million the million alone.
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "benchmark/benchmark.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {
namespace {

// The thesis-numerical truth (plan.yaml), omega in rad/s.
ParameterVector Truth() { return {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)}; }

// One frequency sweep at a_base = 0.01, 38 Hz up and back down, `dwells`
// dwells in all (dwells / 2 each way), 1 % noise; simulated once per size.
const std::vector<Sweep>& SimulatedSweep(int dwells) {
  static std::map<int, std::vector<Sweep>>* cache = new std::map<int, std::vector<Sweep>>;
  auto found = cache->find(dwells);
  if (found != cache->end()) return found->second;
  const int per_direction = dwells / 2;
  SweepPlan sweep;
  sweep.id = "F0.01";
  sweep.held_a_base = 0.01;
  sweep.from = 38.0;                 // [Hz]
  sweep.step = 8.0 / per_direction;  // [Hz]: 38 to 46 Hz
  sweep.to = sweep.from + (per_direction - 1) * sweep.step;
  DwellPlan plan;
  plan.truth = Truth();
  plan.sweeps = {sweep};
  plan.noise.relative_sigma = 0.01;
  plan.noise.seed = 1;
  return cache->emplace(dwells, SimulateDwells(plan)).first->second;
}

// The thesis config's options: its start, w fixed, relative error.
IdentificationOptions GrowthOptions(int threads) {
  IdentificationOptions options;
  options.initial = {130.0, 0.14, 390.0, 7000.0, 1.17e9, HzToRadPerSecond(40.0)};
  options.fixed[kNaturalFrequency] = true;
  options.solve.residual.error = ErrorMeasure::kRelative;
  options.solve.solver.num_threads = threads;
  return options;
}

// A "Name:   12345 kB" line of /proc/self/status, in MB (0 when absent).
double StatusMegabytes(const std::string& name) {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == name + ":") {
      double kilobytes = 0.0;
      status >> kilobytes;
      return kilobytes / 1024.0;
    }
    status.ignore(1 << 20, '\n');
  }
  return 0.0;
}

// Returns the heap's free pages to the system (what an earlier case freed
// would otherwise count as resident before this one) and resets the
// process's peak resident memory (VmHWM) to its current one.
void ResetPeakMemory() {
  malloc_trim(0);
  std::ofstream("/proc/self/clear_refs") << "5";
}

double Seconds(std::chrono::steady_clock::time_point from) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - from).count();
}

// state.range(0) dwells on state.range(1) threads.
void BM_GrowthFit(benchmark::State& state) {
  const int dwells = static_cast<int>(state.range(0));
  const std::vector<Sweep>& sweeps = SimulatedSweep(dwells);
  std::vector<const Sweep*> fitted;
  for (const Sweep& sweep : sweeps) fitted.push_back(&sweep);
  const IdentificationOptions options = GrowthOptions(static_cast<int>(state.range(1)));
  const ParameterVector truth = Truth();
  for (auto _ : state) {
    ResetPeakMemory();
    double resident_before_mb = StatusMegabytes("VmRSS");
    const auto start = std::chrono::steady_clock::now();
    const IdentificationResult result = Identify(fitted, options);
    state.counters["fit_s"] = Seconds(start);
    state.counters["fit_peak_MB"] = StatusMegabytes("VmHWM") - resident_before_mb;
    ResetPeakMemory();
    resident_before_mb = StatusMegabytes("VmRSS");
    const auto covariance_start = std::chrono::steady_clock::now();
    const ParameterUncertainty uncertainty =
        EstimateUncertainty(fitted, options, result.parameters, 0.0, &result);
    state.counters["covariance_s"] = Seconds(covariance_start);
    state.counters["covariance_peak_MB"] = StatusMegabytes("VmHWM") - resident_before_mb;
    benchmark::DoNotOptimize(uncertainty.available);
    const double peak_mb =
        std::max(state.counters["fit_peak_MB"].value, state.counters["covariance_peak_MB"].value);
    state.counters["peak_MB"] = peak_mb;
    state.counters["bytes_per_dwell"] = peak_mb * 1024.0 * 1024.0 / dwells;
    state.counters["iterations"] = result.iterations;
    state.counters["final_cost"] = result.final_cost;
    state.counters["converged"] = result.converged && uncertainty.available;
    double max_rel_error = 0.0;
    for (int i = 0; i < kNumParameters; ++i) {
      max_rel_error =
          std::max(max_rel_error, std::abs(result.parameters[i] - truth[i]) / std::abs(truth[i]));
    }
    state.counters["max_rel_error"] = max_rel_error;
  }
  int total = 0;
  for (const Sweep& sweep : sweeps) total += static_cast<int>(sweep.points.size());
  state.counters["dwells"] = total;
}
BENCHMARK(BM_GrowthFit)
    ->ArgNames({"dwells", "threads"})
    ->ArgsProduct({{1000, 10000, 100000}, {1, 2}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_GrowthFitMillion(benchmark::State& state) { BM_GrowthFit(state); }
BENCHMARK(BM_GrowthFitMillion)
    ->ArgNames({"dwells", "threads"})
    ->ArgsProduct({{1000000}, {1, 2}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
