// Test support for the staged solve and the covariance: simulated datasets of
// the chapter's numerical case at any natural frequency, and the
// descriptions of their fits (one block; mapped blocks; two datasets sharing
// eta_e).
#ifndef DWELLFIT_TESTS_FIT_TEST_SUPPORT_H_
#define DWELLFIT_TESTS_FIT_TEST_SUPPORT_H_

#include <cstdint>
#include <vector>

#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {

// Table 3.1 of the chapter (docs/model.md).
inline const ParameterVector kThesisTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

// The thesis plan's fitted sweeps moved with the natural frequency f0 of
// `truth`: a frequency sweep at a_base 0.01 from f0 - 2 to f0 + 6 Hz and an
// amplitude sweep at f0 + 1.5 Hz, each up and down. With noise the branches
// are labelled by DetectJumps, as for measured data; without, the
// simulator's own labels stand. `form` names the member `truth` is of.
inline std::vector<Sweep> SimulateDataset(const ParameterVector& truth, double relative_sigma,
                                          std::uint64_t seed, ModelForm form = ModelForm{}) {
  const double f0 = RadPerSecondToHz(truth[kNaturalFrequency]);
  SweepPlan frequency;
  frequency.id = "F";
  frequency.kind = SweepKind::kFrequency;
  frequency.held_a_base = 0.01;
  frequency.from = RoundToSignificantDigits(f0 - 2.0, kGridSignificantDigits);
  frequency.to = RoundToSignificantDigits(f0 + 6.0, kGridSignificantDigits);
  frequency.step = 0.1;
  SweepPlan amplitude;
  amplitude.id = "A";
  amplitude.kind = SweepKind::kAmplitude;
  amplitude.held_frequency_hz = f0 + 1.5;
  amplitude.from = 0.002;
  amplitude.to = 0.05;
  amplitude.step = 0.001;
  DwellPlan plan;
  plan.truth = truth;
  plan.form = form;
  plan.sweeps = {frequency, amplitude};
  plan.noise = {relative_sigma, seed};
  std::vector<Sweep> sweeps = SimulateDwells(plan);
  if (relative_sigma > 0.0) DetectJumps(JumpDetectionOptions{}, &sweeps);
  return sweeps;
}

inline std::vector<const Sweep*> Pointers(const std::vector<Sweep>& sweeps) {
  std::vector<const Sweep*> pointers;
  for (const Sweep& sweep : sweeps) pointers.push_back(&sweep);
  return pointers;
}

// The thesis start: every parameter but omega 30 % off, alternately.
inline ParameterVector ThesisStart(const ParameterVector& truth) {
  ParameterVector start = truth;
  const double factors[] = {1.3, 0.7, 1.3, 0.7, 1.3};
  for (int i = 0; i < 5; ++i) start[i] *= factors[i];
  return start;
}

// One dataset's six parameters spread over three blocks in their own
// order: eta_e alone, (mu1, mu2), (delta, alpha, omega); the identity
// mapping, only through blocks.
struct ThreeBlocks {
  double eta_e[1];
  double damping[2];
  double rest[3];

  explicit ThreeBlocks(const ParameterVector& p)
      : eta_e{p[kEtaE]},
        damping{p[kMu1], p[kMu2]},
        rest{p[kDelta], p[kAlpha], p[kNaturalFrequency]} {}

  ParameterVector Values() const {
    return {eta_e[0], damping[0], damping[1], rest[0], rest[1], rest[2]};
  }

  FitDescription Describe(const std::vector<const Sweep*>& sweeps, bool omega_fixed) {
    FitDescription fit;
    fit.blocks = {{eta_e, 1, "eta_e"},
                  {damping, 2, "damping", {"mu1", "mu2"}},
                  {rest, 3, "rest", {"delta", "alpha", "omega"}, {false, false, omega_fixed}}};
    ParameterMap map = {{{eta_e, 0}, {damping, 0}, {damping, 1}, {rest, 0}, {rest, 1}, {rest, 2}}};
    fit.datasets = {{"thesis", sweeps, map}};
    return fit;
  }
};

// Two datasets of one model that differ only in the natural frequency:
// `shared` = {eta_e, mu1, mu2, delta, alpha}, one w per dataset.
struct SharedModel {
  double shared[5];
  double w_a[1];
  double w_b[1];

  SharedModel(const ParameterVector& a, double w_b_rad_s)
      : shared{a[kEtaE], a[kMu1], a[kMu2], a[kDelta], a[kAlpha]},
        w_a{a[kNaturalFrequency]},
        w_b{w_b_rad_s} {}

  ParameterMap MapOf(double* w) {
    return {{{shared, 0}, {shared, 1}, {shared, 2}, {shared, 3}, {shared, 4}, {w, 0}}};
  }

  FitDescription Describe(const std::vector<const Sweep*>& a, const std::vector<const Sweep*>& b) {
    FitDescription fit;
    fit.blocks = {{shared, 5, "shared", {"eta_e", "mu1", "mu2", "delta", "alpha"}},
                  {w_a, 1, "w_A"},
                  {w_b, 1, "w_B"}};
    fit.datasets = {{"A", a, MapOf(w_a)}, {"B", b, MapOf(w_b)}};
    return fit;
  }
};

}  // namespace dwellfit

#endif  // DWELLFIT_TESTS_FIT_TEST_SUPPORT_H_
