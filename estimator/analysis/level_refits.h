// Leave-one-level-out refits: how much each parameter moves when one level
// (a sweep id: its up and down sweeps together) is left out of the fit.
//
// The dwells of one level share its model error, so the statistical
// interval can be much narrower than the estimate's dependence on which
// levels were measured. With L >= kMinLevelsForRefits fitted levels the fit
// is run L more times, each without one level, with the reported fit's
// options and start, side by side on `threads` (the result does not depend
// on the count). Per free parameter and alpha_e, over the usable refits:
// min and max beside the all-level estimate, and the jackknife standard error
//
//   se_J = sqrt((m - 1) / m sum_i (theta_i - theta_bar)^2),
//
// m the usable refits, theta_bar their mean (each refit saw (m - 1) / m of
// the levels). Warnings: an unusable refit, and an all-level estimate
// outside the refits' range (beyond 1e-9 of its magnitude).
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_LEVEL_REFITS_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_LEVEL_REFITS_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// Fewer fitted levels: no refits (two say little about the spread).
inline constexpr int kMinLevelsForRefits = 3;

struct LevelRefit {
  std::string left_out;  // the sweep id left out
  FitStatus status = FitStatus::kInvalidInput;
  bool usable = false;  // counted in the spread
  std::string message;
  double final_cost = 0.0;
  ParameterVector parameters{};  // physical units, omega in rad/s
  double effective_nonlinearity = 0.0;
};

// One quantity's spread over the usable refits (omega in rad/s).
struct RefitSpread {
  int index = 0;          // kNumParameters: alpha_e
  std::string name;       // ParameterName, or "alpha_e"
  double estimate = 0.0;  // the all-level fit's
  double min = 0.0, max = 0.0;
  double jackknife_standard_error = 0.0;
};

struct LevelRefits {
  bool computed = false;            // refits were run
  std::string message;              // what was done, or why not
  std::vector<std::string> levels;  // the fitted levels, in data order
  std::vector<LevelRefit> refits;   // one per level, in its order
  int usable = 0;                   // refits counted in the spread
  std::vector<RefitSpread> spread;  // free parameters in ParameterIndex order, then alpha_e
  std::vector<std::string> warnings;
};

// The refits of the fit of `fitted` with `options` (options.initial: its
// start) at `estimate`. A failed refit does not throw: its status says it.
LevelRefits RefitLeavingOneLevelOut(const std::vector<const Sweep*>& fitted,
                                    const IdentificationOptions& options,
                                    const ParameterVector& estimate, double omega_ref_rad_s,
                                    int threads);

// The spread of each free parameter and alpha_e over the usable refits
// (none with fewer than two); exposed for tests.
std::vector<RefitSpread> SpreadOverRefits(const std::vector<LevelRefit>& refits,
                                          const std::array<bool, kNumParameters>& fixed,
                                          const ParameterVector& estimate, double omega_ref_rad_s,
                                          ModelForm form = ModelForm{});

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_LEVEL_REFITS_H_
