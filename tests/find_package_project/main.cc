// Embeds an installed dwellfit: synthetic dwells from known parameters, a
// ceres::Problem assembled by dwellfit::ProblemBuilder on a parameter block
// owned here, eta_e started 20% off and recovered. Exits nonzero when anything
// is wrong.
#include <cmath>
#include <cstdio>

#include "ceres/ceres.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/residuals/model/stable_root.h"

int main() {
  const dwellfit::ParameterVector truth = {100.0, 0.2, 300.0, 1e4, 9e8,
                                           dwellfit::HzToRadPerSecond(40.0)};
  dwellfit::Sweep sweep;
  sweep.id = "demo";
  for (double hz : {36.0, 37.0, 38.0, 39.0}) {
    dwellfit::DwellPoint d;
    d.drive_frequency_rad_s = dwellfit::HzToRadPerSecond(hz);
    d.a_base = 0.005;
    d.amplitude = dwellfit::ModelAmplitude(truth, d.drive_frequency_rad_s, d.a_base,
                                           dwellfit::Branch::kOnly, 1e-3).a;
    sweep.points.push_back(d);
  }

  double parameters[dwellfit::kNumParameters];
  for (int i = 0; i < dwellfit::kNumParameters; ++i) parameters[i] = truth[i];
  parameters[dwellfit::kEtaE] = 80.0;

  dwellfit::ProblemBuilderOptions builder_options;
  builder_options.residual = dwellfit::ResidualKind::kVertical;
  builder_options.residual_options.error = dwellfit::ErrorMeasure::kRelative;
  builder_options.fixed = {false, true, true, true, true, true};  // fit eta_e only
  const dwellfit::ProblemBuilder builder(builder_options);
  ceres::Problem problem;
  const int blocks = builder.AddSweep(sweep, parameters, &problem);
  builder.ConfigureParameters(parameters, &problem);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-20;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  const double eta_e = parameters[dwellfit::kEtaE];
  const bool ok = blocks == 4 && summary.IsSolutionUsable() &&
                  std::abs(eta_e / truth[dwellfit::kEtaE] - 1.0) < 1e-8 &&
                  sweep.Name() == "demo/up";
  if (!ok) std::printf("%s\n", summary.FullReport().c_str());
  std::printf("%s: %s, %d residual blocks, eta_e = %.9g (truth %.9g) after %d iterations\n",
              ok ? "OK" : "FAILED", sweep.Name().c_str(), blocks, eta_e,
              truth[dwellfit::kEtaE], static_cast<int>(summary.iterations.size()));
  return ok ? 0 : 1;
}
