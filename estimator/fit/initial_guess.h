// An automatic starting point for the identification, from the data alone.
//
// The fit stages (identification.h) need a start within a factor of about 2
// of the minimum. This estimates one from features any sine-dwell test shows,
// with the fixed points of docs/model.md (units: Omega, w in rad/s):
//
//   P(a) = Omega a (mu1 + c mu2 a) / eta_e = a_base sin(gamma),  c = 4 / (3 pi)
//   Q(a) = a D / (2 eta_e)                 = a_base cos(gamma),
//   D    = w^2 + (3/4) alpha a^2 - Omega^2 (1 + delta a^2 / 2)
//        = w^2 + (3/4) alpha_e a^2 - Omega^2,  alpha_e = alpha - (2/3) delta Omega^2.
//
// 1. Backbone points. Where a sweep peaks, Q ~ 0 (D ~ 0) and P ~ a_base: the
//    largest amplitude of each frequency-sweep level (its fold for a hardening
//    up sweep), and the end of the upper branch of each amplitude-sweep level
//    (its upper-branch dwell with the smallest a_base, next to the fold).
// 2. Backbone, D = 0:  Omega_k^2 (1 + delta a_k^2 / 2) = w^2 + (3/4) alpha a_k^2,
//    a straight line in a_k^2 fitted through the backbone points: intercept
//    w^2 (the backbone extrapolated to zero amplitude), slope (3/4) alpha.
// 3. Peak heights, P = a_base at the backbone points:
//    a_base_k / (Omega_k a_k) = mu1 / eta_e + (c mu2 / eta_e) a_k,
//    a straight line in a_k: the damping per unit forcing effectiveness.
// 4. Forcing effectiveness from the dwells off resonance, where
//    |Q| = sqrt(a_base^2 - P^2) is large: |D_i| = 2 eta_e |Q_i| / a_i, a least
//    squares fit through the origin (dominated by the dwells farthest from
//    resonance, whose D is least sensitive to the backbone's error).
// 5. mu1, mu2 from step 3 times eta_e; delta = 0 (over a narrow band only
//    alpha_e is identifiable; the fit may free delta later).
//
// With a single backbone point and neither w nor alpha given, w and eta_e come
// together from step 4 with alpha tied to that point. Parameters the caller
// knows are kept and used in every step (a known w fixes the backbone's
// intercept, a known delta enters D, a known eta_e replaces step 4).
// All least-squares fits are linear and solved by Eigen's QR.
#ifndef DWELLFIT_ESTIMATOR_FIT_INITIAL_GUESS_H_
#define DWELLFIT_ESTIMATOR_FIT_INITIAL_GUESS_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/residuals/model/model_form.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// Parameters the user gave, ParameterIndex order, physical units (omega in
// rad/s); unset entries are estimated.
using KnownParameters = std::array<std::optional<double>, kNumParameters>;

struct InitialGuessReport {
  ParameterVector guess{};  // ParameterIndex order, omega in rad/s
  // How each value was obtained, in the order the steps ran: one line per
  // feature used (backbone points) and one line per parameter, each starting
  // with the parameter's name, e.g. "omega = 251.9 rad/s (40.09 Hz): ...".
  std::vector<std::string> steps;
};

// Estimates a starting point from `sweeps` (frequency and/or amplitude sweeps
// with their branch labels and jumps, as DetectJumps leaves them). Known
// parameters are returned unchanged. Throws InputError when the sweeps carry
// no resonance to estimate from (no frequency-sweep peak inside its band and
// no amplitude sweep reaching the upper branch) or no dwell off resonance.
InitialGuessReport AutomaticInitialGuess(const std::vector<const Sweep*>& sweeps,
                                         const KnownParameters& known);
// The same for `form`'s member: the chapter's estimate with its terms that
// the member replaces (mu2, delta) held at 0; the member's own terms (mu3,
// alpha5, model_form.h) start where given, else at 0, and the fit frees them.
InitialGuessReport AutomaticInitialGuess(const std::vector<const Sweep*>& sweeps,
                                         const KnownParameters& known, ModelForm form);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_INITIAL_GUESS_H_
