// Speed of the identification: the vertical residual with its Jacobian per
// dwell point (read from one block, and through MappedCostFunction from
// three), the whole two-stage thesis-numerical fit (about 260 points; target
// under 20 ms), the measured clamped-beam fit (two levels, 4096 dwells, with
// the bifurcation-range penalty; target under 200 ms), a joint fit of two
// simulated datasets sharing eta_e (mapped blocks), and the response curves
// of an identify run with their curves.csv text. The fits run with the
// residual blocks evaluated on 1 and on 2 threads (the argument); their
// results do not depend on it. Last, a user's whole identify run with its
// figures.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <ostream>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

#include "benchmark/benchmark.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/mapped_cost_function.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/run/run_figures.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {
namespace {

// The allocator policy every dwellfit tool sets first (memory_policy.h), so
// that the fits here run as they do in `identify`.
const bool kToolAllocatorPolicy = KeepFreedMemoryForReuse();

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
  run.options.solve.solver.num_threads = static_cast<int>(state.range(0));
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
// With `mapped`, each dwell reads the parameters from three blocks (eta_e;
// mu1, mu2; delta, alpha, omega) through MappedCostFunction.
void ResidualWithJacobianPerPoint(benchmark::State& state, bool mapped) {
  const ResolvedRun& thesis = Thesis();
  ProblemBuilder builder(ProblemBuilderOptions{});
  ParameterVector start = thesis.options.initial;
  ParameterVector moved = start;
  for (double& value : moved) value *= 1.001;
  FitDescription fit;  // the three blocks' sizes, for the layout
  fit.blocks = {
      {start.data(), 1, "eta_e"}, {start.data() + 1, 2, "damping"}, {start.data() + 3, 3, "rest"}};
  const ParameterMap map = {{{start.data(), 0},
                             {start.data() + 1, 0},
                             {start.data() + 1, 1},
                             {start.data() + 3, 0},
                             {start.data() + 3, 1},
                             {start.data() + 3, 2}}};
  const ParameterLayout layout = LayoutOf(fit, map);
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  for (const Sweep* sweep : thesis.fitted) {
    for (const DwellPoint& point : sweep->points) {
      ceres::CostFunction* cost = builder.MakeResidual(point);
      costs.emplace_back(mapped ? new MappedCostFunction(cost, layout) : cost);
    }
  }
  const double* at_start[] = {start.data(), start.data() + 1, start.data() + 3};
  const double* at_moved[] = {moved.data(), moved.data() + 1, moved.data() + 3};
  double residual;
  double jacobian[kNumParameters];
  double* jacobians[] = {jacobian, jacobian + 1, jacobian + 3};
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

void BM_VerticalResidualWithJacobianPerPoint(benchmark::State& state) {
  ResidualWithJacobianPerPoint(state, false);
}
BENCHMARK(BM_VerticalResidualWithJacobianPerPoint)->Unit(benchmark::kMicrosecond);

void BM_MappedVerticalResidualWithJacobianPerPoint(benchmark::State& state) {
  ResidualWithJacobianPerPoint(state, true);
}
BENCHMARK(BM_MappedVerticalResidualWithJacobianPerPoint)->Unit(benchmark::kMicrosecond);

// One evaluation with Jacobians of the first state.range(0) fitted dwells
// of the measured beam (the vertical residual, one wrapper per dwell,
// compressed as the fit compresses them), alternating between the start and
// a point 0.1 % away, on state.range(1) threads with the evaluator's
// threshold lowered to one residual per thread: what
// ParallelResidualEvaluator::kMinRowsPerThread is measured with (below two
// chunks of ParallelResidualEvaluator's 256 rows nothing splits).
void BM_CompressedDwellEvaluation(benchmark::State& state) {
  const ResolvedRun& beam = ClampedBeam();
  const size_t dwells = static_cast<size_t>(state.range(0));
  const ParameterVector start = beam.options.initial;
  ParameterVector moved = start;
  for (double& value : moved) value *= 1.001;
  ParameterVector point = start;
  ProblemBuilder builder(ProblemBuilderOptions{});
  ParallelResidualEvaluator evaluator({{point.data(), kNumParameters}},
                                      static_cast<int>(state.range(1)), 1);
  std::vector<std::unique_ptr<ceres::CostFunction>> wrappers;
  for (const Sweep* sweep : beam.fitted) {
    for (const DwellPoint& dwell : sweep->points) {
      if (wrappers.size() < dwells)
        wrappers.emplace_back(evaluator.Wrap(builder.MakeResidual(dwell), {point.data()}));
    }
  }
  if (wrappers.size() < dwells) {
    state.SkipWithError("the beam has fewer fitted dwells");
    return;
  }
  const std::unique_ptr<ceres::CostFunction> compressed(evaluator.Compress());
  bool moved_now = false;
  for (auto _ : state) {
    point = moved_now ? moved : start;
    moved_now = !moved_now;
    evaluator.PrepareForEvaluation(true, true);
  }
  state.counters["dwells"] = static_cast<double>(dwells);
}
BENCHMARK(BM_CompressedDwellEvaluation)
    ->ArgNames({"dwells", "threads"})
    ->ArgsProduct({{512, 1024, 2048, 4096}, {1, 2}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

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
// threads:0 is the default setting (one thread per processor available).
void BM_ClampedBeamFit(benchmark::State& state) { RunConfiguredFit(state, ClampedBeam()); }
BENCHMARK(BM_ClampedBeamFit)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

// The same fit with the second-order model (`model: {averaging: second_order}`,
// model_form.h): what its degree-ten G costs a whole fit.
void BM_ClampedBeamFitSecondOrder(benchmark::State& state) {
  static ResolvedRun* beam = LoadCase("clamped-beam-27C");
  beam->options.solve.residual.form = kSecondOrderForm;
  RunConfiguredFit(state, *beam);
}
BENCHMARK(BM_ClampedBeamFitSecondOrder)
    ->ArgName("threads")
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2)
    ->UseRealTime();

// The same on a busy machine: `busy` other processes spin for the whole run,
// each keeping one core occupied, as other jobs do on a shared machine. The
// bar (docs/performance.md): idle, threads:0 at least 1.5x faster than
// threads:1 on two cores; one core busy, at most 10 % slower. One run
// measures both: --benchmark_filter='ClampedBeamFit' with
// --benchmark_enable_random_interleaving=true.
void BM_ClampedBeamFitBusy(benchmark::State& state) {
  std::vector<pid_t> load;
  for (int64_t i = 0; i < state.range(1); ++i) {
    const pid_t pid = fork();
    if (pid == 0) {  // the child only spins until it is killed
      volatile double x = 0.0;
      for (;;) x = x + 1.0;
    }
    if (pid < 0) {
      state.SkipWithError("cannot start a process to load the machine");
      break;
    }
    load.push_back(pid);
  }
  if (load.size() == static_cast<size_t>(state.range(1))) RunConfiguredFit(state, ClampedBeam());
  for (const pid_t pid : load) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
}
BENCHMARK(BM_ClampedBeamFitBusy)
    ->ArgNames({"threads", "busy"})
    ->Args({1, 1})
    ->Args({0, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

// Two simulated datasets of the thesis model (w = 2 pi 40 and 2 pi 43 rad/s,
// 1 % noise), one eta_e, mu1, mu2, delta, alpha block shared and one w block
// each: the staged solve on mapped blocks (520 dwells) from the thesis start.
void BM_TwoDatasetsSharedEtaEFit(benchmark::State& state) {
  static const std::vector<Sweep>* datasets = [] {
    auto* sweeps = new std::vector<Sweep>[2];
    for (int d = 0; d < 2; ++d) {
      const double f0 = d == 0 ? 40.0 : 43.0;
      SweepPlan frequency;
      frequency.id = "F";
      frequency.held_a_base = 0.01;
      frequency.from = f0 - 2.0;
      frequency.to = f0 + 6.0;
      frequency.step = 0.1;
      SweepPlan amplitude = frequency;
      amplitude.id = "A";
      amplitude.kind = SweepKind::kAmplitude;
      amplitude.held_frequency_hz = f0 + 1.5;
      amplitude.from = 0.002;
      amplitude.to = 0.05;
      amplitude.step = 0.001;
      DwellPlan plan;
      plan.truth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(f0)};
      plan.sweeps = {frequency, amplitude};
      sweeps[d] = SimulateDwells(plan);  // noise-free: the simulator's labels
    }
    return sweeps;
  }();
  StagedSolveOptions options;
  options.residual.error = ErrorMeasure::kRelative;
  options.solver.num_threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    double shared[5] = {130.0, 0.14, 390.0, 7000.0, 1.17e9};
    double w[2][1] = {{HzToRadPerSecond(40.2)}, {HzToRadPerSecond(42.8)}};
    FitDescription fit;
    fit.blocks = {{shared, 5, "shared"}, {w[0], 1, "w_A"}, {w[1], 1, "w_B"}};
    for (int d = 0; d < 2; ++d) {
      std::vector<const Sweep*> sweeps;
      for (const Sweep& sweep : datasets[d]) sweeps.push_back(&sweep);
      fit.datasets.push_back(
          {d == 0 ? "A" : "B",
           sweeps,
           {{{shared, 0}, {shared, 1}, {shared, 2}, {shared, 3}, {shared, 4}, {w[d], 0}}}});
    }
    const FitSummary summary = SolveStaged(fit, options);
    benchmark::DoNotOptimize(shared);
    state.counters["iterations"] = summary.iterations;
    state.counters["dwells"] = summary.residual_blocks;
    state.counters["converged"] = summary.converged;
  }
}
BENCHMARK(BM_TwoDatasetsSharedEtaEFit)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The response curves of an identify run and their curves.csv text
// (TraceRunCurves) at the case's fitted estimate, for every fitted and
// validation sweep: 4 curves for the thesis case, 12 for the beam.
void TraceCurvesAtEstimate(benchmark::State& state, ResolvedRun& run) {
  const ParameterVector estimate = FitRun(run).best.parameters;
  std::vector<const Sweep*> sweeps = run.fitted;
  sweeps.insert(sweeps.end(), run.validation.begin(), run.validation.end());
  for (auto _ : state) {
    const RunCurves traced = TraceRunCurves(kFirstOrderForm, estimate, sweeps);
    benchmark::DoNotOptimize(traced.csv.data());
    state.counters["curves"] = static_cast<double>(traced.curves.size());
    state.counters["csv_bytes"] = static_cast<double>(traced.csv.size());
  }
}
void BM_ThesisRunCurves(benchmark::State& state) { TraceCurvesAtEstimate(state, Thesis()); }
BENCHMARK(BM_ThesisRunCurves)->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_ClampedBeamRunCurves(benchmark::State& state) {
  TraceCurvesAtEstimate(state, ClampedBeam());
}
BENCHMARK(BM_ClampedBeamRunCurves)->Unit(benchmark::kMillisecond)->UseRealTime();

// A user's whole `identify` run, as the tool runs it with its defaults: the
// fit, intervals, model error, predictions, curves, every file written and
// the figures drawn by gnuplot (PNG and SVG per sweep), into a fresh folder.
// Targets (two cores): the thesis case under 0.5 s, beam-selected.yaml
// (twelve levels) under 1.5 s.
void IdentifyWithFigures(benchmark::State& state, const std::string& config_path) {
  const std::string out_dir =
      (std::filesystem::temp_directory_path() / "dwellfit-benchmark-identify").string();
  const IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/" + config_path,
                         {{"output_dir", out_dir, "--benchmark"}});
  for (auto _ : state) {
    std::ostringstream printed;
    const std::unique_ptr<IdentifyOutcome> outcome = RunIdentify(config, printed);
    benchmark::DoNotOptimize(outcome.get());
  }
  std::filesystem::remove_all(out_dir);
}
void BM_ThesisIdentifyWithFigures(benchmark::State& state) {
  IdentifyWithFigures(state, "thesis-numerical/beam.yaml");
}
BENCHMARK(BM_ThesisIdentifyWithFigures)->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_ClampedBeamSelectedIdentifyWithFigures(benchmark::State& state) {
  IdentifyWithFigures(state, "clamped-beam-27C/beam-selected.yaml");
}
BENCHMARK(BM_ClampedBeamSelectedIdentifyWithFigures)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
}  // namespace dwellfit

BENCHMARK_MAIN();
