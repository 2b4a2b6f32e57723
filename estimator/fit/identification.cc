#include "dwellfit/estimator/fit/identification.h"

#include <string>

#include "dwellfit/estimator/fit/fit_description.h"

namespace dwellfit {

IdentificationResult Identify(const std::vector<const Sweep*>& fitted,
                              const IdentificationOptions& options) {
  IdentificationResult result;
  result.parameters = options.initial;
  std::string error;
  // The start here; the solve's options where they enter SolveStaged.
  if (!options.InitialIsValid(&error)) {
    result.status = FitStatus::kInvalidInput;
    result.message = error;
    return result;
  }
  const FitDescription fit =
      SingleBlockFit(fitted, options.fixed, &result.parameters, options.solve.residual.form);
  static_cast<FitSummary&>(result) = SolveStaged(fit, options.solve);
  return result;
}

}  // namespace dwellfit
