// The measured level's noise in the intervals (errors in the level).
//
// A dwell's base level a_b is measured too (process_traces takes it from the
// base channel), and the fit evaluates the model at the measured value as if
// it were exact. Where a dwell's amplitude depends steeply on the level (near
// a fold, d ln a / d ln a_b >> 1) a 0.5 % error in a_b moves the residual by
// far more than the amplitude's own noise, and intervals from the residuals'
// scatter alone are too narrow exactly where a design puts its dwells.
//
// Model. Dwell i's measured level is a_b,i (1 + kappa_i e_g), kappa_i =
// a_base_sigma / a_base (DwellPoint::a_base_sigma), e_g ~ N(0, 1) one draw per
// level group g: a frequency sweep's dwells share one level (the mean of their
// measured levels) and so one draw; each dwell of an amplitude sweep has its
// own. To first order the level's error moves residual i by
//
//   dr_i = h_i kappa_i e_g,   h_i = dr_i / d ln a_b = eta_e dr_i / d eta_e
//
// (the model sees the forcing only through eta_e a_b: response_model.h), and
// the fit's estimate by dp = -(J^T J)^-1 J^T dr. The covariance of the
// estimate the fit made (a sandwich, not a refit) is then
//
//   C = (s'^2 / s^2) C_0 + sum_g (C_0 / s^2) v_g v_g^T (C_0 / s^2),
//   v_g = sum_{i in g} kappa_i h_i J_i^T                          (k-vector)
//
// with C_0 = s^2 (J^T J)^-1 the covariance without the level (penalty rows
// included where C_0 has them). s^2, the scatter of the residuals, holds the
// level's share too: E[2 F] = s'^2 (n - k) + sum_g (|h_g|^2 - v_g^T (C_0 / s^2) v_g),
// |h_g|^2 = sum_{i in g} kappa_i^2 h_i^2, so the amplitude's own variance is
// s'^2 = (2 F - sum_g (...)) / (n - k), kept at no less than s^2 / 10 (a
// warning says when the stated level noise explains more of the scatter than
// that leaves). Where every dwell is divided by its point sigma (s = 1) s' = s.
//
// Only dwells with a_base_sigma count; without any, C = C_0 exactly.
#ifndef DWELLFIT_ESTIMATOR_ANALYSIS_LEVEL_NOISE_H_
#define DWELLFIT_ESTIMATOR_ANALYSIS_LEVEL_NOISE_H_

#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// The share of s^2 below which s'^2 is not taken (see above).
inline constexpr double kLevelNoiseFloorShare = 0.1;

struct LevelNoise {
  int groups = 0;  // level draws counted (0: no dwell states its level's sigma)
  // C - C_0 of the free parameters, physical units.
  Eigen::Matrix<double, kNumParameters, kNumParameters> added =
      Eigen::Matrix<double, kNumParameters, kNumParameters>::Zero();
  double noise_sigma = 0.0;  // s', the amplitude's own noise
  std::string warning;       // set when s'^2 was held at its floor
};

// h = dr / d ln a_b of a dwell's residual at `p` from its derivative in
// eta_e: the model sees the forcing only through eta_e a_b.
inline double LevelSlope(const ParameterVector& p, double dr_d_eta_e) {
  return p[kEtaE] * dr_d_eta_e;
}

// The level draws of `fitted` (see above): a frequency sweep's dwells that
// state a_base_sigma form one, each such dwell of an amplitude sweep one of
// its own. Dwells without a_base_sigma (or with a_base <= 0) are in none.
std::vector<std::vector<const DwellPoint*>> LevelDraws(const std::vector<const Sweep*>& fitted);

// The level's term for the fit of `fitted` at `estimate`, from C_0
// (`covariance`, zero on fixed parameters), its noise `noise_sigma` (s),
// `data_cost` (F), `degrees_of_freedom` (n - k) and whether s is known
// (`standardised`). groups = 0 when no dwell states a_base_sigma or a
// residual cannot be evaluated (then `warning` says so).
LevelNoise EstimateLevelNoise(
    const std::vector<const Sweep*>& fitted, const IdentificationOptions& options,
    const ParameterVector& estimate,
    const Eigen::Matrix<double, kNumParameters, kNumParameters>& covariance, double noise_sigma,
    double data_cost, int degrees_of_freedom, bool standardised);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_ANALYSIS_LEVEL_NOISE_H_
