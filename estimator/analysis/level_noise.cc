#include "dwellfit/estimator/analysis/level_noise.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "ceres/cost_function.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/problem_builder.h"

namespace dwellfit {
namespace {

using Vector6 = Eigen::Matrix<double, kNumParameters, 1>;
using Matrix6 = Eigen::Matrix<double, kNumParameters, kNumParameters>;

// One level draw's sums: v_g and |h_g|^2.
struct LevelGroup {
  Vector6 v = Vector6::Zero();
  double hh = 0.0;
};

// Adds dwell `point`'s kappa h J^T and (kappa h)^2 to `group`; false where its
// residual cannot be evaluated at `estimate`.
bool AddDwell(const ProblemBuilder& builder, const DwellPoint& point,
              const IdentificationOptions& options, const ParameterVector& estimate,
              LevelGroup* group) {
  const std::unique_ptr<ceres::CostFunction> cost(builder.MakeResidual(point));
  const double* parameters[] = {estimate.data()};
  double residual = 0.0;
  double row[kNumParameters];
  double* jacobians[] = {row};
  if (!cost->Evaluate(parameters, &residual, jacobians)) return false;
  const double kappa = *point.a_base_sigma / point.a_base;
  const double h = LevelSlope(estimate, row[kEtaE]);
  Vector6 j;
  for (int p = 0; p < kNumParameters; ++p) j[p] = options.fixed[p] ? 0.0 : row[p];
  if (!(std::isfinite(h) && j.allFinite())) return false;
  group->v += kappa * h * j;
  group->hh += kappa * kappa * h * h;
  return true;
}

}  // namespace

std::vector<std::vector<const DwellPoint*>> LevelDraws(const std::vector<const Sweep*>& fitted) {
  std::vector<std::vector<const DwellPoint*>> draws;
  for (const Sweep* sweep : fitted) {
    const bool shared = sweep->kind == SweepKind::kFrequency;
    bool opened = false;
    for (const DwellPoint& point : sweep->points) {
      if (!point.a_base_sigma || !(point.a_base > 0.0)) continue;
      if (!shared || !opened) draws.emplace_back();
      opened = true;
      draws.back().push_back(&point);
    }
  }
  return draws;
}

LevelNoise EstimateLevelNoise(const std::vector<const Sweep*>& fitted,
                              const IdentificationOptions& options, const ParameterVector& estimate,
                              const Matrix6& covariance, double noise_sigma, double data_cost,
                              int degrees_of_freedom, bool standardised) {
  LevelNoise out;
  out.noise_sigma = noise_sigma;
  if (!(noise_sigma > 0.0) || degrees_of_freedom < 1) return out;
  ProblemBuilderOptions builder_options;
  builder_options.residual_options = options.solve.residual;
  const ProblemBuilder builder(builder_options);
  std::vector<LevelGroup> groups;
  for (const std::vector<const DwellPoint*>& draw : LevelDraws(fitted)) {
    groups.emplace_back();
    for (const DwellPoint* point : draw) {
      if (!AddDwell(builder, *point, options, estimate, &groups.back())) {
        out.warning = StringPrintf(
            "the level's noise is left out of the intervals: the residual of the dwell at %.6g "
            "Hz cannot be evaluated at the estimate",
            RadPerSecondToHz(point->drive_frequency_rad_s));
        return out;
      }
    }
  }
  if (groups.empty()) return out;
  const double s2 = noise_sigma * noise_sigma;
  const Matrix6 scaled = covariance / s2;  // (J^T J)^-1, penalty rows included
  double level_share = 0.0;                // E[2 F] the level accounts for
  for (const LevelGroup& g : groups) {
    const Vector6 u = scaled * g.v;
    out.added += u * u.transpose();
    level_share += g.hh - g.v.dot(u);
  }
  out.groups = static_cast<int>(groups.size());
  if (standardised) return out;
  double own = (2.0 * data_cost - level_share) / degrees_of_freedom;
  if (own < kLevelNoiseFloorShare * s2) {
    out.warning = StringPrintf(
        "the stated level sigmas (a_base_sigma) account for %.0f %% of the residuals' scatter: "
        "the amplitude's own noise is held at %.0f %% of the scatter; check a_base_sigma",
        100.0 * level_share / (2.0 * data_cost), 100.0 * kLevelNoiseFloorShare);
    own = kLevelNoiseFloorShare * s2;
  }
  out.noise_sigma = std::sqrt(own);
  out.added += (own / s2 - 1.0) * covariance;
  return out;
}

}  // namespace dwellfit
