// Convergence family: does the fit reach the truth from the automatic start
// for every model variant, for hardening and softening, with and without
// jumps in the data, and in any unit of the amplitudes and of time?
//
// The family (docs/convergence-family.md) is generated from two base cases,
// each a truth and a dwell plan of one frequency sweep "F" and one amplitude
// sweep "A", up and down:
//   thesis     the chapter's Table 3.1 (hardening; the plan of
//              datasets/thesis-numerical),
//   softening  eta_e 50, mu1 0.5, mu2 100, delta 1e3, alpha -4e8, w 60 Hz.
// Each member transforms a base case and names the parameters it fixes (at
// their true values; every other guess is left to the data):
//   amplitude unit  a in a unit 1/lambda times the base's, lambda 1e-6 ... 1e3:
//                   eta_e * lambda, mu2 / lambda, delta and alpha / lambda^2
//                   (a_base and the plan unchanged: the same physics);
//   time unit       frequencies times s (1e-2, 1e2): w, mu1, mu2 times s,
//                   alpha and eta_e times s^2, the plan's frequencies times s;
//   variants        all six free; delta fixed; the Duffing form (truth with
//                   delta = mu2 = 0, both fixed at 0); w fixed;
//   no jumps        the base levels divided by 10: weakly nonlinear sweeps
//                   without a jump;
//   penalties       all free, with the bifurcation-range penalty (eq. 3.17)
//                   enforcing every measured jump, in three amplitude units.
// Every member is simulated noise-free (SimulateDwells) and fitted through
// the one path of a run (ResolveRun, FitRun) on a base config whose data,
// selection, guesses and fixed set the member replaces.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_CONVERGENCE_FAMILY_H_
#define DWELLFIT_ESTIMATOR_STUDIES_CONVERGENCE_FAMILY_H_

#include <array>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {

// A fit reaches the truth when every free parameter is within this relative
// error of it.
inline constexpr double kFamilyTolerance = 1e-6;

struct FamilyMember {
  std::string name;  // e.g. "thesis a*1e-06 all-free"
  DwellPlan plan;    // truth and sweeps "F" and "A"
  std::array<bool, kNumParameters> fixed{};
  bool bifurcation_penalty = false;  // enforce every measured jump
};

struct FamilyOutcome {
  FamilyMember member;
  FitStatus status = FitStatus::kInvalidInput;
  std::string message;
  double max_relative_error = 0.0;  // over the free parameters

  bool ReachedTruth() const {
    return status == FitStatus::kConverged && max_relative_error <= kFamilyTolerance;
  }
  // Reported as converged, yet not at the truth: what must never happen.
  bool SilentlyWrong() const {
    return status == FitStatus::kConverged && !(max_relative_error <= kFamilyTolerance);
  }
};

// The documented family, in a fixed order.
std::vector<FamilyMember> ConvergenceFamily();

// Simulates `member` and fits it on `base`'s settings from the automatic
// start. Never throws: a run that cannot start gives kInvalidInput.
FamilyOutcome RunFamilyMember(const IdentifyConfig& base, const FamilyMember& member);

// The outcomes as a Markdown report (errors as powers of ten: deterministic).
std::string ConvergenceFamilyMarkdown(const std::vector<FamilyOutcome>& outcomes);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_CONVERGENCE_FAMILY_H_
