// Identification: the staged solve (staged_solve.h) of one dataset whose six
// parameters form one block. An embedder with shared parameters or priors
// describes a FitDescription and calls SolveStaged.
#ifndef DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_H_
#define DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_H_

#include <vector>

#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/staged_solve.h"

namespace dwellfit {

// A staged solve's summary and where it left the parameters. For
// FitStatus::kInvalidInput the parameters are options.initial and `message`
// names the invalid field. Each stage's `values` and `held_at_bound` are in
// ParameterIndex order.
struct IdentificationResult : FitSummary {
  ParameterVector parameters{};  // physical units, omega in rad/s
};

// Runs the configured stages on `fitted` from options.initial. Invalid
// options give kInvalidInput.
IdentificationResult Identify(const std::vector<const Sweep*>& fitted,
                              const IdentificationOptions& options);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_H_
