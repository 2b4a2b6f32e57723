// Where to dwell next: candidate dwells within a rig's limits, ranked by the
// expected gain in what the user targets per second of test time
// (docs/next-dwell.md).
//
// What the dwells so far know (DesignBasis): the estimate theta and the
// covariance C = s^2 (J^T J)^-1 = I^-1 of the free parameters, I = J^T J / s^2
// the Fisher information, J the vertical-error residuals' Jacobian, s the
// residual's noise. A candidate dwell at (Omega, a_b) on the branch it lands
// on adds one residual r = a - a_model(Omega, a_b; theta) (or its relative
// form), whose row is g = dr/dtheta at theta (the VerticalErrorResidual
// functor's own Jacobian, zero for fixed parameters). Then, with u = C g:
//
//   D-optimal:      gain = log det(I + g g^T / s^2) - log det(I)
//                        = log(1 + g^T C g / s^2)              [matrix determinant lemma]
//   a quantity q:   gain = c^T C c - c^T C' c = (c^T u)^2 / (s^2 + g^T u),
//                   C' = C - u u^T / (s^2 + g^T u)              [Sherman-Morrison]
//                   c = dq/dtheta at theta
//
// A segment of n dwells (a short stepped sweep in one direction) adds the
// rows G (n x k) at once. With their noise covariance N (s^2 I_n, plus the
// measured level's term when DesignBasis::level_relative_sigma is set) and
// M = N + G C G^T the same formulas read gain = log det M - log det N and
// gain = (G C c)^T M^-1 (G C c) [Woodbury], C' = C - (G C)^T M^-1 (G C); a
// single dwell is n = 1. Its test time is the sum of its dwells', each
// settling from the one before.
//
// Test time of a candidate (seconds): settle + record, with
//
//   settle = (k + ln(1 + d)) / lambda,   d = |a_new - a_now| / a_new,
//   lambda = mu1 + (2/pi) mu2 a_new,
//
// lambda the decay rate of a disturbance of the new steady state: half the
// slow flow's trace nu (2 k1 + 3 k2 a) at a = a_new (docs/model.md, "Stability
// and folds"), which is mu1, the linear decay (free vibration decays as
// exp(-mu1 t)), where the amplitude is small. k is the time constants a unit
// relative step needs, and ln(1 + d) the extra ones a transient that starts d
// times the new amplitude away needs to fall to the same e^-k share (a step
// onto the other branch, d ~ 10, adds 2.4 time constants).
//
// Landing branch: at (Omega, a_b) with two stable roots (the hysteresis
// range) a dwell stays on the branch it comes from when that branch still
// reaches a_b, and jumps onto the other where it ends; coming from a
// single-valued state (`only`) it lands on the stable root nearer the present
// amplitude. With one stable root it is `only`.
#ifndef DWELLFIT_ESTIMATOR_DESIGN_NEXT_DWELL_H_
#define DWELLFIT_ESTIMATOR_DESIGN_NEXT_DWELL_H_

#include <array>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/stable_root.h"
#include "dwellfit/residuals/model/sweep_vocabulary.h"

namespace dwellfit {

using ParameterGradient = Eigen::Matrix<double, kNumParameters, 1>;

// What a next dwell should teach.
enum class TargetKind {
  kDOptimal,               // every free parameter: log det of the information
  kParameter,              // one parameter's variance
  kEffectiveNonlinearity,  // alpha_e = alpha - (2/3) delta Omega_ref^2
  kModalFrequency,         // omega(a) [Hz] at a response amplitude a
  kJumpFrequency,          // a frequency sweep's jump [Hz] at a base level
};

struct DesignTarget {
  TargetKind kind = TargetKind::kDOptimal;
  ParameterIndex parameter = kEtaE;     // kParameter
  double amplitude = 0.0;               // kModalFrequency: a, the data's amplitude unit
  double level = 0.0;                   // kJumpFrequency: a_b, the data's level unit
  JumpKind jump = JumpKind::kJumpDown;  // kJumpFrequency
  // "d_optimal", "eta_e", "alpha_e", "omega_at=0.003", "jump_down_hz=0.01".
  std::string Name() const;
};

// Reads a target named as DesignTarget::Name() writes it. False, with the
// reason in `error`, for anything else.
bool ParseDesignTarget(const std::string& text, DesignTarget* target, std::string* error);

// Where the rig is now: the last dwell's frequency, level and branch.
struct RigState {
  double frequency_hz = 0.0;
  double level = 0.0;  // base level a_b, the data's unit
  Branch branch = Branch::kOnly;
  bool IsValid(std::string* error) const;
};

// What the rig can do. Candidates form the grid present + i * step_min within
// |i * step_min| <= step_max and the range, on each axis; step_max 0 holds
// that axis at its present value.
struct RigLimits {
  double frequency_min_hz = 0.0, frequency_max_hz = 0.0;
  double frequency_step_min_hz = 0.0, frequency_step_max_hz = 0.0;
  double level_min = 0.0, level_max = 0.0;
  double level_step_min = 0.0, level_step_max = 0.0;
  bool IsValid(std::string* error) const;
};

struct DesignOptions {
  DesignTarget target;
  double settle_time_constants = 5.0;  // k of the cost model (>= 0)
  double recording_seconds = 2.0;      // recording time of one dwell [s] (>= 0)
  // s of a new dwell in the residual's unit; 0: the fit's own s. A fit whose
  // dwells were divided by their point sigmas (s = 1) needs it given.
  double noise_sigma = 0.0;
  int top = 5;  // candidates printed with their intervals
  // n >= 2: also rank segments of n dwells stepping along one axis, up or
  // down, by a multiple of its smallest step (1: single dwells only; <= 20).
  int segment_dwells = 1;
  int max_candidates = 1000000;  // the grid may hold at most this many
  bool IsValid(std::string* error) const;
};

// What the dwells so far know. `covariance` is C = I^-1 over the free
// parameters in physical units (omega in rad/s), zero for fixed ones.
struct DesignBasis {
  ParameterVector estimate{};
  std::array<bool, kNumParameters> fixed{};
  ParameterMatrix covariance = ParameterMatrix::Zero();
  double noise_sigma = 0.0;         // s, the residual's unit
  double interval_quantile = 1.96;  // of the reported 95 % intervals
  // n - k of the fit behind it, and whether s is known (every dwell divided
  // by its point sigma): what other intervals' quantiles need.
  int degrees_of_freedom = 0;
  bool noise_known = false;
  ResidualOptions residual;  // error measure and floor of the dwells' residual
  // kappa: the relative standard deviation of one new dwell's measured level
  // (0: exact). A candidate's residuals then carry, besides s^2, the level's
  // kappa^2 h h^T (h_i = dr_i / d ln a_b): shared by a frequency segment's
  // dwells (one mean level, kappa^2 / n), each dwell's own in a level segment.
  double level_relative_sigma = 0.0;
  double omega_ref_rad_s = 0.0;  // Omega_ref of alpha_e
};

// A single dwell, or a segment of `dwells` dwells: the first at
// (frequency_hz, level), each next one step further. The branch, jump and
// amplitude are the first dwell's; the times and the gain the whole
// segment's.
struct Candidate {
  double frequency_hz = 0.0, level = 0.0;
  int dwells = 1;
  double frequency_step_hz = 0.0, level_step = 0.0;  // between a segment's dwells
  Branch branch = Branch::kOnly;                     // the branch the first dwell lands on
  bool jumps = false;                                // it leaves the present branch for the other
  double amplitude = 0.0;                            // its predicted a at the estimate
  double settle_seconds = 0.0, record_seconds = 0.0;
  double gain = 0.0;  // nats (D-optimal) or the variance reduction in q's unit^2
  double gain_per_second = 0.0;
};

// The rows g of a candidate's dwells, one per dwell.
using CandidateRows = Eigen::Matrix<double, Eigen::Dynamic, kNumParameters>;

struct Recommendation {
  // The basis used: the given one, its covariance rescaled by
  // (noise_sigma / basis.noise_sigma)^2 when DesignOptions::noise_sigma is set.
  DesignBasis basis;
  std::vector<Candidate> ranked;  // by gain_per_second, best first
  DesignTarget target;
  double quantity = 0.0;           // q at the estimate (not for kDOptimal)
  double quantity_variance = 0.0;  // c^T C c now
  RigState state;                  // the present state
  double present_amplitude = 0.0;  // the model's amplitude there
};

// The model's amplitude and branch after a step from the branch `from` at
// amplitude `a_now` to (f, level) (the landing rule above); false where no
// stable root is found. `jumps`: the branch it came from ends before (f, level).
// `form`: the response model's (model_form.h).
bool LandingPoint(ModelForm form, const ParameterVector& p, Branch from, double a_now,
                  double frequency_hz, double level, Branch* branch, double* amplitude,
                  bool* jumps);

// g = dr/dtheta of one dwell whose model amplitude is `amplitude` on `branch`,
// at the estimate; zero on the fixed parameters. False where undefined.
// `level_slope`, when given: h = dr / d ln a_b = eta_e dr / d eta_e.
bool ResidualGradient(const DesignBasis& basis, double frequency_hz, double level, Branch branch,
                      double amplitude, ParameterGradient* g, double* level_slope = nullptr);

// c = dq/dtheta of the target's quantity and its value (central differences
// for omega(a) and the jump frequency); zero on fixed parameters. False where
// q is undefined at the estimate (no jump at that level, say).
bool QuantityGradient(const DesignBasis& basis, const DesignTarget& target, double* value,
                      ParameterGradient* c);

// Walks a candidate's dwells from the present branch and amplitude: sets
// its branch, jump, amplitude and settling and recording times (`options`'
// cost model) and returns its rows, and its residuals' noise covariance N
// (s^2 I plus the level's term above). False where a dwell has no stable root
// or its row is undefined.
bool WalkCandidate(const DesignBasis& basis, Branch from, double a_now,
                   const DesignOptions& options, Candidate* candidate, CandidateRows* rows,
                   Eigen::MatrixXd* noise);

// The covariance after adding the dwells whose rows are G with noise
// covariance N (Woodbury: C - (G C)^T (N + G C G^T)^-1 G C).
ParameterMatrix CovarianceAfter(const ParameterMatrix& covariance, const CandidateRows& rows,
                                const Eigen::MatrixXd& noise);

// Ranks every candidate of the limits' grid from `state`. Options and limits
// must be valid (IsValid); throws InputError when the target's quantity is
// undefined at the estimate or the grid is larger than max_candidates.
Recommendation RecommendNextDwell(const DesignBasis& basis, const RigState& state,
                                  const RigLimits& limits, const DesignOptions& options);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DESIGN_NEXT_DWELL_H_
