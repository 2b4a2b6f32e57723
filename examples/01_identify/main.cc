// The shortest use of dwellfit: load sine-dwell sweeps from a CSV file, find
// their jumps and a starting point from the data, fit the six parameters and
// print each estimate with its 95 % interval.
//   01_identify sweeps.csv   (e.g. datasets/thesis-numerical/sweeps.csv)
// Exits non-zero when the file cannot be read or the fit does not converge.
#include <cstdio>
#include <exception>
#include <vector>

#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/initial_guess.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s sweeps.csv\n", argv[0]);
    return 2;
  }
  try {
    // 1. The sweeps, with each jump and each dwell's branch labelled.
    std::vector<dwellfit::Sweep> sweeps = dwellfit::LoadSweepsCsv(argv[1]).sweeps;
    dwellfit::DetectJumps(dwellfit::JumpDetectionOptions{}, &sweeps);
    std::vector<const dwellfit::Sweep*> fitted;
    for (const dwellfit::Sweep& sweep : sweeps) fitted.push_back(&sweep);

    // 2. The fit: a start estimated from the data, the vertical error in
    // ln(a) (noise on a dwell's amplitude is multiplicative).
    dwellfit::IdentificationOptions options;
    options.initial = dwellfit::AutomaticInitialGuess(fitted, {}).guess;
    options.solve.residual.error = dwellfit::ErrorMeasure::kRelative;
    dwellfit::IdentificationResult fit = dwellfit::Identify(fitted, options);

    // 3. The estimates with their 95 % intervals: identify's, the profile of
    // the fitted cost (the fit goes on where a profile finds a lower cost).
    const dwellfit::ParameterUncertainty u =
        dwellfit::EstimateUncertaintyAtMinimum(fitted, options, 0.0, &fit);
    std::printf("%s: %s\n", dwellfit::FitStatusName(fit.status), fit.message.c_str());
    if (!fit.converged) return 1;
    if (!u.available) {
      std::printf("no intervals: %s\n", u.message.c_str());
      return 1;
    }
    for (int i = 0; i < dwellfit::kNumParameters; ++i) {
      std::printf("%-8s %12.6g  95%% interval [%.6g, %.6g]\n", dwellfit::ParameterName(i),
                  fit.parameters[i], u.ci95_low[i], u.ci95_high[i]);
    }
    for (const std::string& warning : u.warnings) std::printf("warning: %s\n", warning.c_str());
    return 0;
  } catch (const dwellfit::InputError& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 1;
  }
}
