// The all-roots residual (all six roots of eq. 3.11 by Eigen's companion
// matrix, the nearest stable one lifted) against the vertical error by Newton
// refinement (section 3.2.4), on the same dwells in one run: every fitted
// dwell of datasets/thesis-numerical, value alone and value with Jacobian,
// alternating between the config's start and a point 0.1 % away (as a
// solver's steps do). After the runs the program prints the ratio of the
// all-roots time to the vertical time; the chapter found the all-roots
// algorithm the slower (target: Newton at least 20 times faster).
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "benchmark/benchmark.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {
namespace {

const ResolvedRun& Thesis() {
  static const ResolvedRun* thesis = new ResolvedRun(ResolveRun(LoadIdentifyConfig(
      std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml")));
  return *thesis;
}

// state.range(0): 0 vertical, 1 all roots; state.range(1): 1 with Jacobian;
// `form`: the response model (model_form.h).
void DwellResidual(benchmark::State& state, ModelForm form) {
  const ResolvedRun& thesis = Thesis();
  ProblemBuilderOptions options;
  options.residual = state.range(0) == 0 ? ResidualKind::kVertical : ResidualKind::kAllRoots;
  options.residual_options = thesis.options.solve.residual;
  options.residual_options.form = form;
  const ProblemBuilder builder(options);
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  for (const Sweep* sweep : thesis.fitted) {
    for (const DwellPoint& point : sweep->points) costs.emplace_back(builder.MakeResidual(point));
  }
  ParameterVector start = thesis.options.initial;
  ParameterVector moved = start;
  for (double& value : moved) value *= 1.001;
  const double* at_start[] = {start.data()};
  const double* at_moved[] = {moved.data()};
  double residual;
  double jacobian[kNumParameters];
  double* jacobians[] = {jacobian};
  double** with_jacobian = state.range(1) == 1 ? jacobians : nullptr;
  bool moved_now = false;
  for (auto _ : state) {
    const double* const* blocks = moved_now ? at_moved : at_start;
    moved_now = !moved_now;
    for (const auto& cost : costs) {
      if (!cost->Evaluate(blocks, &residual, with_jacobian)) state.SkipWithError("not evaluable");
      benchmark::DoNotOptimize(residual);
    }
  }
  state.SetLabel(std::string(form.second_order()   ? "second_order "
                             : form.family_terms() ? "family "
                                                   : "") +
                 ResidualKindName(options.residual) +
                 (with_jacobian ? " value+Jacobian" : " value"));
  state.counters["dwells"] = static_cast<double>(costs.size());
  state.counters["ns_per_dwell"] =
      benchmark::Counter(static_cast<double>(state.iterations() * costs.size()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_DwellResidual(benchmark::State& state) { DwellResidual(state, kFirstOrderForm); }
BENCHMARK(BM_DwellResidual)
    ->ArgNames({"all_roots", "jacobian"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMicrosecond);

// The same with the second-order model (G of degree ten: the roots take the
// companion matrix's path), what `model: {averaging: second_order}` costs.
void BM_SecondOrderDwellResidual(benchmark::State& state) {
  DwellResidual(state, kSecondOrderForm);
}
BENCHMARK(BM_SecondOrderDwellResidual)
    ->ArgNames({"all_roots", "jacobian"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMicrosecond);

// The same with a member of the family (model_form.h: mu3 and alpha5 in the
// entries of mu2 and delta, here at the thesis start's 390 and 1.3e4, small
// terms): G of degree ten, the roots on the certificate's and companion
// matrix's path, what `model: {damping: cubic, backbone: quintic}` costs.
void BM_FamilyDwellResidual(benchmark::State& state) {
  ModelForm form;
  form.damping = DampingTerm::kCubic;
  form.backbone = BackboneTerm::kQuintic;
  DwellResidual(state, form);
}
BENCHMARK(BM_FamilyDwellResidual)
    ->ArgNames({"all_roots", "jacobian"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Unit(benchmark::kMicrosecond);

// The console output, and each run's CPU time per iteration kept by its
// label (CPU time: the machine may be shared, and the ratio should not see it).
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type == Run::RT_Iteration && run.iterations > 0) {
        seconds_[run.report_label] = run.cpu_accumulated_time / run.iterations;
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void PrintRatios() const {
    for (const char* what : {" value", " value+Jacobian"}) {
      const auto vertical = seconds_.find(std::string("vertical") + what);
      const auto all_roots = seconds_.find(std::string("all_roots") + what);
      if (vertical == seconds_.end() || all_roots == seconds_.end()) continue;
      std::printf("all_roots / vertical CPU time,%s: %.1f\n", what,
                  all_roots->second / vertical->second);
    }
  }

 private:
  std::map<std::string, double> seconds_;
};

}  // namespace
}  // namespace dwellfit

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  dwellfit::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.PrintRatios();
  benchmark::Shutdown();
  return 0;
}
