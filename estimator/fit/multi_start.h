// Multi-start: the identification from several starting points, keeping the
// best (lowest final cost), with how many starts reached it.
//
// Start 0 is the given start; then, when given, the automatic start
// (initial_guess.h); the rest spread each free parameter of start 0 by a
// factor exp(U(-ln s, ln s)), s = `spread`, from a seeded generator. Results
// do not depend on the thread count.
#ifndef DWELLFIT_ESTIMATOR_FIT_MULTI_START_H_
#define DWELLFIT_ESTIMATOR_FIT_MULTI_START_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dwellfit/estimator/fit/identification.h"

namespace dwellfit {

// Each start is a whole fit: more is likely a typo.
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
  int reached_best = 0;                 // starts whose estimate matches the best's
  // Starts whose fit is not usable or not finite: never the best unless all.
  int failed = 0;
};

// The starting points IdentifyMultiStart uses.
std::vector<ParameterVector> MultiStartPoints(const IdentificationOptions& options,
                                              const std::optional<ParameterVector>& automatic,
                                              const MultiStartOptions& multi_start);

// Runs Identify from every start and keeps the usable fit of lowest cost
// (else start 0's). A start "reached the best" when each free parameter is
// within 1e-5 of the best, relative. Invalid `multi_start` options give
// best.status = kInvalidInput, naming the field.
MultiStartResult IdentifyMultiStart(const std::vector<const Sweep*>& fitted,
                                    const IdentificationOptions& options,
                                    const std::optional<ParameterVector>& automatic,
                                    const MultiStartOptions& multi_start);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_MULTI_START_H_
