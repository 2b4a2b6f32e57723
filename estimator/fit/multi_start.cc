#include "dwellfit/estimator/fit/multi_start.h"

#include <algorithm>
#include <boost/random/uniform_real_distribution.hpp>
#include <cmath>
#include <random>

#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "tbb/parallel_for.h"
#include "tbb/task_arena.h"

namespace dwellfit {

bool MultiStartOptions::IsValid(std::string* error) const {
  if (starts < 1 || starts > kMaxStarts) {
    *error = "multi_start.starts must be from 1 to " + std::to_string(kMaxStarts) +
             " (each start is a whole fit)";
    return false;
  }
  if (!(spread > 1.0) || !std::isfinite(spread)) {
    *error = "multi_start.spread must be a factor greater than 1";
    return false;
  }
  if (threads < 1) {
    *error = "multi_start.threads must be at least 1";
    return false;
  }
  return true;
}

std::vector<ParameterVector> MultiStartPoints(const IdentificationOptions& options,
                                              const std::optional<ParameterVector>& automatic,
                                              const MultiStartOptions& multi_start) {
  std::vector<ParameterVector> starts = {options.initial};
  if (automatic && static_cast<int>(starts.size()) < multi_start.starts &&
      *automatic != options.initial) {
    ParameterVector start = *automatic;
    for (int i = 0; i < kNumParameters; ++i) {
      if (options.fixed[i]) start[i] = options.initial[i];
    }
    starts.push_back(start);
  }
  // Boost.Random's distribution is one implementation everywhere, so a seed
  // gives the same starts on every platform.
  std::mt19937_64 generator(multi_start.seed);
  boost::random::uniform_real_distribution<double> log_factor(-std::log(multi_start.spread),
                                                              std::log(multi_start.spread));
  while (static_cast<int>(starts.size()) < multi_start.starts) {
    ParameterVector start = options.initial;
    for (int i = 0; i < kNumParameters; ++i) {
      const double factor = std::exp(log_factor(generator));  // drawn for every entry
      if (!options.fixed[i]) start[i] *= factor;
    }
    starts.push_back(start);
  }
  return starts;
}

namespace {

// A fit that solved to finite parameters: only such can be the best.
bool Usable(const IdentificationResult& fit) {
  return fit.IsSolutionUsable() && std::all_of(fit.parameters.begin(), fit.parameters.end(),
                                               [](double v) { return std::isfinite(v); });
}

}  // namespace

MultiStartResult IdentifyMultiStart(const std::vector<const Sweep*>& fitted,
                                    const IdentificationOptions& options,
                                    const std::optional<ParameterVector>& automatic,
                                    const MultiStartOptions& multi_start) {
  MultiStartResult result;
  std::string error;
  if (!multi_start.IsValid(&error)) {
    result.best.parameters = options.initial;
    result.best.status = FitStatus::kInvalidInput;
    result.best.message = error;
    result.starts = {options.initial};
    result.final_costs = {0.0};
    return result;
  }
  result.starts = MultiStartPoints(options, automatic, multi_start);
  const int n = static_cast<int>(result.starts.size());
  std::vector<IdentificationResult> fits(n);
  const int parallel_starts = std::min(multi_start.threads, n);
  // The starts share the machine's threads.
  IdentificationOptions per_start = options;
  per_start.solve.solver.num_threads = std::max(
      1, ResolveThreadCount(options.solve.solver.num_threads) / std::max(parallel_starts, 1));
  tbb::task_arena arena(parallel_starts);
  arena.execute([&] {
    tbb::parallel_for(0, n, [&](int i) {
      IdentificationOptions start = per_start;
      start.initial = result.starts[i];
      fits[i] = Identify(fitted, start);
    });
  });

  int best_usable = -1;
  for (int i = 0; i < n; ++i) {
    result.final_costs.push_back(fits[i].final_cost);
    if (!Usable(fits[i])) {
      ++result.failed;
      continue;
    }
    // Lowest cost wins; ties go to the earlier start.
    if (best_usable < 0 || fits[i].final_cost < fits[best_usable].final_cost) best_usable = i;
  }
  result.best_start = std::max(best_usable, 0);
  result.best = fits[result.best_start];
  for (int i = 0; i < n; ++i) {
    bool same = Usable(fits[i]);
    for (int j = 0; j < kNumParameters && same; ++j) {
      if (options.fixed[j]) continue;
      const double reference = std::abs(result.best.parameters[j]) > 0.0
                                   ? std::abs(result.best.parameters[j])
                                   : std::max(std::abs(options.initial[j]), 1.0);
      same = std::abs(fits[i].parameters[j] - result.best.parameters[j]) <= 1e-5 * reference;
    }
    result.reached_best += same;
  }
  return result;
}

}  // namespace dwellfit
