// Multi-start: the identification from several starting points, keeping the
// best (lowest final cost), with how many starts reached it.
//
// Start 0 is the given start; then, when given, the automatic start
// (initial_guess.h); the rest spread each free parameter of start 0 by a
// factor exp(U(-ln s, ln s)), s = `spread`, drawn from a seeded generator, so
// the same options give the same starts. Fixed parameters and parameters at 0
// keep their value. Starts run on `threads` threads; results do not depend on
// the thread count.
#ifndef DWELLFIT_ESTIMATOR_FIT_MULTI_START_H_
#define DWELLFIT_ESTIMATOR_FIT_MULTI_START_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dwellfit/estimator/fit/identification.h"

namespace dwellfit {

// The most starts a run may ask for: each start is a whole fit, and a larger
// count is more likely a typo than a need.
inline constexpr int kMaxStarts = 1000;

struct MultiStartOptions {
  int starts = 1;       // total number of fits, 1 to kMaxStarts
  double spread = 3.0;  // s: random starts within a factor s either way, > 1
  std::uint64_t seed = 1;
  int threads = 2;  // >= 1
  bool IsValid(std::string* error) const;
};

struct MultiStartResult {
  IdentificationResult best;
  int best_start = 0;                   // index into `starts`
  std::vector<ParameterVector> starts;  // every starting point, in order
  std::vector<double> final_costs;      // of each start
  std::vector<bool> converged;          // of each start
  int reached_best = 0;                 // starts whose estimate matches the best's
  // Starts whose fit failed (IdentificationResult::IsSolutionUsable() false, or parameters
  // that are not finite): never the best unless all failed.
  int failed = 0;
};

// The starting points MultiStart uses (exposed for tests and reports).
std::vector<ParameterVector> MultiStartPoints(const IdentificationOptions& options,
                                              const std::optional<ParameterVector>& automatic,
                                              const MultiStartOptions& multi_start);

// Runs Identify from every start and keeps the usable fit of lowest cost
// (the first start's fit, with its status, when none is usable). A start
// "reached the best" when each free parameter is within 1e-5 of the best
// estimate, relative to that estimate's magnitude (or to the start's scale
// for a parameter at 0). Invalid `multi_start` options give
// best.status = FitStatus::kInvalidInput, naming the field.
MultiStartResult IdentifyMultiStart(const std::vector<const Sweep*>& fitted,
                                    const IdentificationOptions& options,
                                    const std::optional<ParameterVector>& automatic,
                                    const MultiStartOptions& multi_start);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_MULTI_START_H_
