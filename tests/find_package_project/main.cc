// Embeds an installed dwellfit: synthetic dwells from known parameters, a
// FitDescription on a parameter block owned here (eta_e free, started 20 %
// off, the rest fixed), dwellfit::SolveStaged and the covariance of the
// block. Exits nonzero when anything is wrong.
#include <cmath>
#include <cstdio>

#include "dwellfit/estimator/analysis/block_covariance.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/residuals/model/stable_root.h"

int main() {
  const dwellfit::ParameterVector truth = {100.0, 0.2, 300.0,
                                           1e4,   9e8, dwellfit::HzToRadPerSecond(40.0)};
  dwellfit::Sweep sweep;
  sweep.id = "demo";
  for (double hz : {36.0, 37.0, 38.0, 39.0}) {
    dwellfit::DwellPoint d;
    d.drive_frequency_rad_s = dwellfit::HzToRadPerSecond(hz);
    d.a_base = 0.005;
    d.amplitude =
        dwellfit::ModelAmplitude(dwellfit::kFirstOrderForm, truth, d.drive_frequency_rad_s,
                                 d.a_base, dwellfit::Branch::kOnly, 1e-3)
            .a;
    // 1 % off the model, alternating: the covariance has noise to measure.
    d.amplitude *= hz == 36.0 || hz == 38.0 ? 1.01 : 0.99;
    sweep.points.push_back(d);
  }

  double parameters[dwellfit::kNumParameters];
  for (int i = 0; i < dwellfit::kNumParameters; ++i) parameters[i] = truth[i];
  parameters[dwellfit::kEtaE] = 80.0;

  dwellfit::FitDescription fit;
  dwellfit::FitBlock block;
  block.values = parameters;
  block.size = dwellfit::kNumParameters;
  block.name = "parameters";
  block.fixed = {false, true, true, true, true, true};  // fit eta_e only
  fit.blocks = {block};
  fit.datasets = {{"demo", {&sweep}, dwellfit::IdentityMap(parameters)}};

  dwellfit::StagedSolveOptions options;
  options.stages = {dwellfit::ResidualKind::kVertical};
  options.residual.error = dwellfit::ErrorMeasure::kRelative;
  options.solver.function_tolerance = 1e-14;
  const dwellfit::FitSummary summary = dwellfit::SolveStaged(fit, options);
  const dwellfit::BlockCovariance covariance =
      dwellfit::EstimateBlockCovariance(fit, options.residual);

  const double eta_e = parameters[dwellfit::kEtaE];
  const double se = covariance.standard_error[dwellfit::kEtaE];
  const bool ok = summary.IsSolutionUsable() && summary.residual_blocks == 4 &&
                  std::abs(eta_e / truth[dwellfit::kEtaE] - 1.0) < 0.02 && covariance.available &&
                  se > 0.0 && std::abs(eta_e - truth[dwellfit::kEtaE]) < 4.0 * se &&
                  sweep.Name() == "demo/up";
  std::printf("%s: %s, %s: %s; eta_e = %.6g +/- %.2g (truth %.6g)\n", ok ? "OK" : "FAILED",
              sweep.Name().c_str(), dwellfit::FitStatusName(summary.status),
              summary.message.c_str(), eta_e, se, truth[dwellfit::kEtaE]);
  if (!covariance.available) std::printf("covariance: %s\n", covariance.message.c_str());
  return ok ? 0 : 1;
}
