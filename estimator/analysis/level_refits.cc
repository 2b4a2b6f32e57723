#include "dwellfit/estimator/analysis/level_refits.h"

#include <algorithm>
#include <cmath>

#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/identification.h"
#include "tbb/parallel_for.h"
#include "tbb/task_arena.h"

namespace dwellfit {
namespace {

// One refit: the fit of every sweep outside level `left_out`.
LevelRefit Refit(const std::vector<const Sweep*>& fitted, const IdentificationOptions& options,
                 const std::string& left_out, double omega_ref_rad_s) {
  std::vector<const Sweep*> kept;
  for (const Sweep* sweep : fitted) {
    if (sweep->id != left_out) kept.push_back(sweep);
  }
  const IdentificationResult result = Identify(kept, options);
  LevelRefit refit;
  refit.left_out = left_out;
  refit.status = result.status;
  refit.message = result.message;
  refit.final_cost = result.final_cost;
  refit.parameters = result.parameters;
  refit.effective_nonlinearity =
      EffectiveNonlinearity(options.solve.residual.form, result.parameters, omega_ref_rad_s);
  refit.usable =
      result.IsSolutionUsable() && std::all_of(result.parameters.begin(), result.parameters.end(),
                                               [](double v) { return std::isfinite(v); });
  return refit;
}

RefitSpread SpreadOf(ModelForm form, int index, double estimate,
                     const std::vector<double>& values) {
  RefitSpread spread;
  spread.index = index;
  spread.name = index < kNumParameters ? ParameterName(form, index) : "alpha_e";
  spread.estimate = estimate;
  spread.min = *std::min_element(values.begin(), values.end());
  spread.max = *std::max_element(values.begin(), values.end());
  const double m = static_cast<double>(values.size());
  double mean = 0.0;
  for (double v : values) mean += v / m;
  double sum = 0.0;
  for (double v : values) sum += (v - mean) * (v - mean);
  spread.jackknife_standard_error = std::sqrt((m - 1.0) / m * sum);
  return spread;
}

// The refits' warnings (see the header).
std::vector<std::string> Warnings(const LevelRefits& r) {
  std::vector<std::string> warnings;
  for (const LevelRefit& refit : r.refits) {
    if (refit.usable) continue;
    warnings.push_back("the refit without " + refit.left_out + " gave no usable solution (" +
                       FitStatusName(refit.status) + "): " + refit.message);
  }
  for (const RefitSpread& s : r.spread) {
    const double slack = 1e-9 * std::abs(s.estimate);
    if (s.estimate >= s.min - slack && s.estimate <= s.max + slack) continue;
    warnings.push_back(StringPrintf(
        "%s = %.6g from all %zu levels lies outside its leave-one-level-out refits' range "
        "%.6g..%.6g: the levels disagree on it, or the all-level fit found another minimum",
        s.name.c_str(), s.estimate, r.levels.size(), s.min, s.max));
  }
  return warnings;
}

// The fitted sweeps' levels (sweep ids) in data order.
std::vector<std::string> FittedLevels(const std::vector<const Sweep*>& fitted) {
  std::vector<std::string> levels;
  for (const Sweep* sweep : fitted) {
    if (std::find(levels.begin(), levels.end(), sweep->id) == levels.end()) {
      levels.push_back(sweep->id);
    }
  }
  return levels;
}

}  // namespace

std::vector<RefitSpread> SpreadOverRefits(const std::vector<LevelRefit>& refits,
                                          const std::array<bool, kNumParameters>& fixed,
                                          const ParameterVector& estimate, double omega_ref_rad_s,
                                          ModelForm form) {
  std::vector<RefitSpread> spread;
  std::vector<const LevelRefit*> usable;
  for (const LevelRefit& refit : refits) {
    if (refit.usable) usable.push_back(&refit);
  }
  if (usable.size() < 2) return spread;
  for (int j = 0; j <= kNumParameters; ++j) {  // kNumParameters: alpha_e
    const bool parameter = j < kNumParameters;
    if (parameter ? fixed[j] : fixed[kAlpha] && (fixed[kDelta] || !form.has_inertia())) continue;
    std::vector<double> values;
    for (const LevelRefit* refit : usable) {
      values.push_back(parameter ? refit->parameters[j] : refit->effective_nonlinearity);
    }
    spread.push_back(SpreadOf(
        form, j, parameter ? estimate[j] : EffectiveNonlinearity(form, estimate, omega_ref_rad_s),
        values));
  }
  return spread;
}

LevelRefits RefitLeavingOneLevelOut(const std::vector<const Sweep*>& fitted,
                                    const IdentificationOptions& options,
                                    const ParameterVector& estimate, double omega_ref_rad_s,
                                    int threads) {
  LevelRefits result;
  result.levels = FittedLevels(fitted);
  const int count = static_cast<int>(result.levels.size());
  if (count < kMinLevelsForRefits) {
    result.message = StringPrintf(
        "not computed: %d level%s fitted, the leave-one-level-out refits need %d or more", count,
        count == 1 ? "" : "s", kMinLevelsForRefits);
    return result;
  }
  IdentificationOptions refit_options = options;
  refit_options.solve.solver.num_threads = 1;
  result.refits.resize(count);
  tbb::task_arena arena(
      std::max(1, std::min({threads, count, tbb::this_task_arena::max_concurrency()})));
  arena.execute([&] {
    tbb::parallel_for(0, count, [&](int i) {
      result.refits[i] = Refit(fitted, refit_options, result.levels[i], omega_ref_rad_s);
    });
  });
  for (const LevelRefit& refit : result.refits) result.usable += refit.usable;
  result.spread = SpreadOverRefits(result.refits, options.fixed, estimate, omega_ref_rad_s,
                                   options.solve.residual.form);
  result.computed = true;
  result.warnings = Warnings(result);
  result.message = StringPrintf(
      "%d refits, each without one of the %d fitted levels, from the reported fit's start; %d "
      "usable%s",
      count, count, result.usable, result.usable < 2 ? " (fewer than 2: no spread)" : "");
  return result;
}

}  // namespace dwellfit
