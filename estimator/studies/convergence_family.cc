#include "dwellfit/estimator/studies/convergence_family.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {
namespace {

// Sweep "F" of the frequency [Hz] at base level `held`, or "A" of a_base at
// the drive frequency `held` [Hz]: from, to, step of the stepped control.
SweepPlan Sweep(SweepKind kind, double held, double from, double to, double step) {
  SweepPlan sweep;
  sweep.id = kind == SweepKind::kFrequency ? "F" : "A";
  sweep.kind = kind;
  (kind == SweepKind::kFrequency ? sweep.held_a_base : sweep.held_frequency_hz) = held;
  sweep.from = from;
  sweep.to = to;
  sweep.step = step;
  return sweep;
}

// The chapter's numerical case (Table 3.1) with the fitted sweeps of
// datasets/thesis-numerical/plan.yaml.
DwellPlan ThesisCase() {
  DwellPlan plan;
  plan.truth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};
  plan.sweeps = {Sweep(SweepKind::kFrequency, 0.01, 38.0, 46.0, 0.1),
                 Sweep(SweepKind::kAmplitude, 41.5, 0.002, 0.05, 0.001)};
  return plan;
}

// A softening mode: both sweeps cross the jumps (at a_base 0.02 between 58.7
// and 59.6 Hz; at 59.3 Hz between a_base 0.013 and 0.039).
DwellPlan SofteningCase() {
  DwellPlan plan;
  plan.truth = {50.0, 0.5, 100.0, 1e3, -4e8, HzToRadPerSecond(60.0)};
  plan.sweeps = {Sweep(SweepKind::kFrequency, 0.02, 52.0, 62.0, 0.1),
                 Sweep(SweepKind::kAmplitude, 59.3, 0.002, 0.05, 0.001)};
  return plan;
}

// The same physics with a in a unit 1/lambda times the base's.
DwellPlan InAmplitudeUnit(DwellPlan plan, double lambda) {
  ParameterVector& p = plan.truth;
  p[kEtaE] *= lambda;
  p[kMu2] /= lambda;
  p[kDelta] /= lambda * lambda;
  p[kAlpha] /= lambda * lambda;
  return plan;
}

// The same physics with every frequency s times the base's.
DwellPlan InTimeUnit(DwellPlan plan, double s) {
  ParameterVector& p = plan.truth;
  p[kNaturalFrequency] *= s;
  p[kMu1] *= s;
  p[kMu2] *= s;
  p[kAlpha] *= s * s;
  p[kEtaE] *= s * s;
  for (SweepPlan& sweep : plan.sweeps) {
    if (sweep.kind == SweepKind::kFrequency) {
      sweep.from *= s;
      sweep.to *= s;
      sweep.step *= s;
    } else {
      sweep.held_frequency_hz *= s;
    }
  }
  return plan;
}

// Weakly nonlinear: every level divided by 10, so that no sweep jumps.
DwellPlan WithoutJumps(DwellPlan plan) {
  for (SweepPlan& sweep : plan.sweeps) {
    if (sweep.kind == SweepKind::kFrequency) {
      sweep.held_a_base /= 10.0;
    } else {
      sweep.from /= 10.0;
      sweep.to /= 10.0;
      sweep.step /= 10.0;
    }
  }
  return plan;
}

struct Variant {
  const char* name;
  std::array<bool, kNumParameters> fixed;
  bool duffing;  // truth with delta = mu2 = 0
};

const Variant kAllFree{"all-free", {}, false};
const Variant kDeltaFixed{"delta-fixed", {false, false, false, true, false, false}, false};
const Variant kDuffing{"duffing", {false, false, true, true, false, false}, true};
const Variant kOmegaFixed{"w-fixed", {false, false, false, false, false, true}, false};

FamilyMember Member(const std::string& base, const std::string& transform, DwellPlan plan,
                    const Variant& variant) {
  if (variant.duffing) {
    plan.truth[kDelta] = 0.0;
    plan.truth[kMu2] = 0.0;
  }
  return {base + " " + transform + " " + variant.name, std::move(plan), variant.fixed, false};
}

// The base config on the member's sweeps: both fitted, none validated, the
// fixed parameters at their true values, every other guess from the data.
IdentifyConfig MemberConfig(const IdentifyConfig& base, const FamilyMember& member) {
  IdentifyConfig config = base;
  config.fit_sweeps = {{"F", std::nullopt}, {"A", std::nullopt}};
  config.validate_sweeps.clear();
  config.jump_overrides.clear();
  config.omega_ref_rad_s.reset();
  config.multi_start.starts = 1;
  if (member.bifurcation_penalty) {
    BifurcationRangeOptions& range = config.identification.solve.penalties.bifurcation_range;
    range.enabled = true;
    range.enforce = {JumpTarget::kFrequencyJumpUp, JumpTarget::kFrequencyJumpDown,
                     JumpTarget::kAmplitudeJumpUp, JumpTarget::kAmplitudeJumpDown};
  }
  for (int i = 0; i < kNumParameters; ++i) {
    config.identification.fixed[i] = member.fixed[i];
    config.initial_guess[i].reset();
    if (member.fixed[i]) config.initial_guess[i] = member.plan.truth[i];
    config.identification.initial[i] = member.plan.truth[i];  // placeholder, replaced
  }
  return config;
}

// The error as a class that does not move with the last bits of a platform's
// arithmetic: below 1e-9, below the tolerance, or its power of ten.
std::string ErrorClass(double error) {
  if (!std::isfinite(error)) return "not finite";
  if (error <= 1e-9) return "< 1e-9";
  if (error <= kFamilyTolerance) return "< 1e-6";
  return StringPrintf("1e%+03d", static_cast<int>(std::floor(std::log10(error))));
}

}  // namespace

std::vector<FamilyMember> ConvergenceFamily() {
  std::vector<FamilyMember> family;
  const std::vector<std::pair<std::string, DwellPlan>> bases = {{"thesis", ThesisCase()},
                                                                {"softening", SofteningCase()}};
  for (const auto& [name, base] : bases) {
    for (double lambda : {1e-6, 1e-4, 1e-2, 1.0, 1e3}) {
      for (const Variant& variant : {kAllFree, kDeltaFixed, kDuffing, kOmegaFixed}) {
        family.push_back(
            Member(name, StringPrintf("a*%g", lambda), InAmplitudeUnit(base, lambda), variant));
      }
    }
    for (double s : {1e-2, 1e2}) {
      for (const Variant& variant : {kAllFree, kDuffing}) {
        family.push_back(Member(name, StringPrintf("t/%g", s), InTimeUnit(base, s), variant));
      }
    }
    for (const Variant& variant : {kAllFree, kDeltaFixed}) {
      family.push_back(Member(name, "no-jumps", WithoutJumps(base), variant));
    }
    for (double lambda : {1e-6, 1.0, 1e3}) {
      FamilyMember member =
          Member(name, StringPrintf("a*%g", lambda), InAmplitudeUnit(base, lambda), kAllFree);
      member.name += " penalty";
      member.bifurcation_penalty = true;
      family.push_back(std::move(member));
    }
  }
  return family;
}

FamilyOutcome RunFamilyMember(const IdentifyConfig& base, const FamilyMember& member) {
  FamilyOutcome outcome;
  outcome.member = member;
  try {
    const ResolvedRun run = ResolveRun(MemberConfig(base, member), SimulateDwells(member.plan));
    const IdentificationResult result = FitRun(run).best;
    outcome.status = result.status;
    outcome.message = result.message;
    for (int i = 0; i < kNumParameters; ++i) {
      if (member.fixed[i]) continue;
      const double truth = member.plan.truth[i];
      const double error = std::abs(result.parameters[i] - truth) / std::abs(truth);
      outcome.max_relative_error =
          std::isnan(error) ? error : std::max(outcome.max_relative_error, error);
      if (std::isnan(error)) break;
    }
  } catch (const InputError& error) {
    outcome.status = FitStatus::kInvalidInput;
    outcome.message = error.what();
  }
  return outcome;
}

std::string ConvergenceFamilyMarkdown(const std::vector<FamilyOutcome>& outcomes) {
  const auto reached = std::count_if(outcomes.begin(), outcomes.end(),
                                     [](const FamilyOutcome& o) { return o.ReachedTruth(); });
  const auto silent = std::count_if(outcomes.begin(), outcomes.end(),
                                    [](const FamilyOutcome& o) { return o.SilentlyWrong(); });
  std::ostringstream md;
  md << "<!-- Generated by build/tools/convergence_family; do not edit. -->\n"
     << "# Convergence family\n\n"
     << "Each member is simulated noise-free and fitted from the automatic start (every guess "
        "not fixed is found from the data); the family and its transformations are described "
        "in `estimator/studies/convergence_family.h`. A member reaches the truth when the fit "
        "converges with every free parameter within "
     << StringPrintf("%g", kFamilyTolerance) << " of it (relative).\n\n"
     << "**" << reached << " of " << outcomes.size() << " members reach the truth; " << silent
     << " report convergence away from it.**\n\n"
     << "| member | status | largest relative error | reached |\n|---|---|---|---|\n";
  for (const FamilyOutcome& o : outcomes) {
    md << "| " << o.member.name << " | " << FitStatusName(o.status) << " | "
       << ErrorClass(o.max_relative_error) << " | " << (o.ReachedTruth() ? "yes" : "**no**")
       << " |\n";
  }
  return md.str();
}

}  // namespace dwellfit
