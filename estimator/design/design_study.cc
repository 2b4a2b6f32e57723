#include "dwellfit/estimator/design/design_study.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/rig_config_reader.h"
#include "dwellfit/estimator/analysis/block_covariance.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/design/next_dwell_run.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {
namespace {

// The dwells measured so far: each sweep's traces, in measurement order.
struct Measured {
  std::vector<std::string> order;  // sweep ids, first appearance
  std::map<std::string, std::vector<DwellTrace>> traces;
  int dwells = 0;
};

// Takes one dwell on the rig and files its traces under `sweep`.
RigDwell TakeDwell(VirtualRig* rig, double f_hz, double level, const std::string& sweep,
                   SweepDirection direction, SweepKind kind, Measured* measured, ArmRun* arm) {
  RigDwell dwell = rig->Dwell(f_hz, level, sweep, direction);
  dwell.trace.kind = kind;
  if (!measured->traces.count(sweep)) measured->order.push_back(sweep);
  measured->traces[sweep].push_back(dwell.trace);
  ++measured->dwells;
  arm->dwells.push_back({sweep, f_hz, level, dwell.settle_seconds, dwell.record_seconds});
  arm->elapsed_seconds = rig->elapsed_seconds();
  return dwell;
}

// The dwell points of every sweep so far (ProcessTraces per sweep, so that a
// frequency sweep's level is the mean of its measured levels, as
// process_traces writes it).
std::vector<Sweep> ProcessedSweeps(const Measured& measured,
                                   const TraceProcessingOptions& processing) {
  std::vector<Sweep> sweeps;
  for (const std::string& id : measured.order) {
    ProcessedTraces processed = ProcessTraces(measured.traces.at(id), processing);
    for (Sweep& sweep : processed.sweeps) sweeps.push_back(std::move(sweep));
  }
  return sweeps;
}

// The study's quantities' values and 95 % half-widths from a design basis,
// simultaneous for the four or each its own (PrecisionTarget::simultaneous).
void Intervals(const DesignBasis& basis, bool simultaneous, StudyFit* fit) {
  const int parameter[kStudyQuantities] = {-1, kEtaE, kNaturalFrequency, kMu1};
  fit->interval_quantile = simultaneous
                               ? SimultaneousIntervalQuantile(
                                     basis.noise_known, basis.degrees_of_freedom, kStudyQuantities)
                               : basis.interval_quantile;
  for (int i = 0; i < kStudyQuantities; ++i) {
    ParameterGradient c;
    double value = 0.0;
    if (parameter[i] < 0) {
      QuantityGradient(basis, {TargetKind::kEffectiveNonlinearity}, &value, &c);
    } else {
      value = basis.estimate[parameter[i]];
      c = ParameterGradient::Unit(parameter[i]);
    }
    fit->value[i] = value;
    fit->half_width[i] =
        fit->interval_quantile * std::sqrt(std::max(c.dot(basis.covariance * c), 0.0));
  }
}

// The largest half-width / (bound |value|): the target is met at <= 1.
double WorstRatio(const StudyFit& fit, const PrecisionTarget& target, int* worst) {
  double ratio = 0.0;
  for (int i = 0; i < kStudyQuantities; ++i) {
    const double r = fit.half_width[i] / (target.relative_half_width[i] * std::abs(fit.value[i]));
    const double q = std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
    if (q >= ratio) {
      ratio = q;
      if (worst) *worst = i;
    }
  }
  return ratio;
}

// The config of a fit of `sweeps` from `start`: every parameter free, every
// sweep fitted, none validated, one solver thread.
IdentifyConfig FitConfig(const IdentifyConfig& base, const std::vector<Sweep>& sweeps,
                         const ParameterVector& start) {
  IdentifyConfig config = base;
  config.fit_sweeps.clear();
  config.validate_sweeps.clear();
  config.jump_overrides.clear();
  std::set<std::string> ids;
  for (const Sweep& sweep : sweeps) {
    if (ids.insert(sweep.id).second) config.fit_sweeps.push_back({sweep.id, std::nullopt});
  }
  for (int j = 0; j < kNumParameters; ++j) config.initial_guess[j] = start[j];
  config.identification.initial = start;
  config.identification.fixed.fill(false);
  config.identification.solve.solver.num_threads = 1;
  config.multi_start.starts = 1;
  return config;
}

// Fits the dwells so far from `start`; the basis is set when the fit gives
// intervals.
StudyFit FitDwells(const DesignStudyCase& study, const Measured& measured,
                   const ParameterVector& start, const PrecisionTarget& target,
                   ParameterVector* estimate, DesignBasis* basis) {
  StudyFit fit;
  fit.dwells = measured.dwells;
  const std::vector<Sweep> sweeps = ProcessedSweeps(measured, study.processing);
  const IdentifyConfig config = FitConfig(study.config, sweeps, start);
  ResolvedRun run;
  try {
    run = ResolveRun(config, sweeps);
  } catch (const InputError&) {  // too few dwells for the free parameters: no fit yet
    fit.status = FitStatus::kInvalidInput;
    return fit;
  }
  const IdentificationResult result = FitRun(run).best;
  fit.status = result.status;
  if (result.status != FitStatus::kConverged && result.status != FitStatus::kNoConvergence) {
    return fit;
  }
  const double omega_ref = config.omega_ref_rad_s.value_or(result.parameters[kNaturalFrequency]);
  std::string why;
  if (!DesignBasisFromFit(run.fitted, run.options, result.parameters, omega_ref, basis, &why)) {
    // Not the next start: a warm start from an estimate the data cannot
    // tell apart (a parameter on its bound) stays there.
    fit.status = FitStatus::kUnidentifiable;
    return fit;
  }
  *estimate = result.parameters;
  fit.has_intervals = true;
  Intervals(*basis, target.simultaneous, &fit);
  fit.worst_ratio = WorstRatio(fit, target, nullptr);
  fit.met = fit.worst_ratio <= 1.0;
  return fit;
}

// Records a fit; true when it is the first to meet the target.
bool Record(const StudyFit& fit, ArmRun* arm) {
  arm->fits.push_back(fit);
  arm->fits.back().elapsed_seconds = arm->elapsed_seconds;
  if (!fit.met || arm->reached) return false;
  arm->reached = true;
  arm->time_to_target_seconds = arm->elapsed_seconds;
  arm->dwells_to_target = fit.dwells;
  return true;
}

// Whether the last fit with intervals holds the truth.
void JudgeCoverage(const DesignStudyCase& study, ArmRun* arm) {
  const std::array<double, kStudyQuantities> truth = StudyTruth(study);
  arm->covers.fill(false);
  arm->covers_all = false;
  for (auto fit = arm->fits.rbegin(); fit != arm->fits.rend(); ++fit) {
    if (!fit->has_intervals) continue;
    arm->covers_all = true;
    for (int i = 0; i < kStudyQuantities; ++i) {
      arm->covers[i] = std::abs(fit->value[i] - truth[i]) <= fit->half_width[i];
      arm->covers_all = arm->covers_all && arm->covers[i];
    }
    return;
  }
}

VirtualRig MakeRig(const DesignStudyCase& study, std::uint64_t seed) {
  RigOptions options = study.rig;
  options.noise_seed = seed;
  return VirtualRig(study.plan.truth, options);
}

ParameterVector InitialGuess(const IdentifyConfig& config) {
  ParameterVector start = config.identification.initial;
  for (int j = 0; j < kNumParameters; ++j) {
    if (config.initial_guess[j]) start[j] = *config.initial_guess[j];
  }
  return start;
}

}  // namespace

const char* StudyQuantityName(int quantity) {
  constexpr const char* kNames[kStudyQuantities] = {"alpha_e", "eta_e", "w", "mu1"};
  return NameOf(kNames, quantity);
}

bool PrecisionTarget::IsValid(std::string* error) const {
  for (int i = 0; i < kStudyQuantities; ++i) {
    if (!(relative_half_width[i] > 0.0 && std::isfinite(relative_half_width[i]))) {
      *error = StringPrintf("the target's bound on %s must be positive, got %g",
                            StudyQuantityName(i), relative_half_width[i]);
      return false;
    }
  }
  return true;
}

bool DesignStudyOptions::IsValid(std::string* error) const {
  if (!target.IsValid(error)) return false;
  if (seeds < 1 || start_step_factor < 1 || refit_dwells < 0 || max_closed_loop_dwells < 1 ||
      hysteresis_steps < 1) {
    *error = "seeds, start_step_factor and hysteresis_steps must be >= 1, refit_dwells >= 0";
    return false;
  }
  if (!(time_budget_seconds > 0.0) || !(frequency_step_max_hz >= 0.0) || !(level_step_max >= 0.0) ||
      !(settle_time_constants >= 0.0)) {
    *error =
        "time_budget_seconds must be positive, frequency_step_max_hz, level_step_max and "
        "settle_time_constants >= 0";
    return false;
  }
  return true;
}

DesignStudyCase LoadDesignStudyCase(const std::string& name, const std::string& config_path,
                                    const std::string& plan_path, const std::string& rig_path) {
  DesignStudyCase study;
  study.name = name;
  study.config = LoadIdentifyConfig(config_path);
  study.plan = ReadDwellPlan(plan_path);
  const RigConfig rig = ReadRigConfig(rig_path);
  study.rig = rig.rig;
  study.processing = rig.processing;
  std::string error;
  if (!study.plan.IsValid(&error)) throw InputError(plan_path, 0, "", error);
  // next_dwell's ranking and the study's quantities are the chapter's terms'.
  if (study.plan.form.family_terms() ||
      study.config.identification.solve.residual.form.family_terms()) {
    throw InputError(study.plan.form.family_terms() ? plan_path : config_path, 0, "model",
                     "the design study ranks dwells for the chapter's terms (mu2, delta) only; "
                     "remove damping: and backbone: from model:");
  }
  if (study.plan.noise.relative_sigma != 0.0) {
    throw InputError(plan_path, 0, "noise",
                     "the rig adds its own noise (the rig config's noise.relative_sigma); set "
                     "the plan's to 0 or leave it out");
  }
  return study;
}

std::array<double, kStudyQuantities> StudyTruth(const DesignStudyCase& study) {
  DesignBasis basis;
  basis.estimate = study.plan.truth;
  basis.omega_ref_rad_s =
      study.config.omega_ref_rad_s.value_or(study.plan.truth[kNaturalFrequency]);
  StudyFit fit;
  Intervals(basis, false, &fit);  // the values only
  return fit.value;
}

ArmRun RunStandardProtocol(const DesignStudyCase& study, const DesignStudyOptions& options,
                           std::uint64_t seed) {
  ArmRun arm{"standard", seed};
  VirtualRig rig = MakeRig(study, seed);
  Measured measured;
  ParameterVector estimate = InitialGuess(study.config);
  DesignBasis basis;
  for (int pass = 1; !arm.reached && arm.elapsed_seconds < options.time_budget_seconds; ++pass) {
    for (const SweepPlan& plan : study.plan.sweeps) {
      rig.Rest();  // every sweep starts from rest
      const std::string id = pass == 1 ? plan.id : StringPrintf("%s+%d", plan.id.c_str(), pass);
      for (SweepDirection direction : plan.directions) {
        int in_sweep = 0;
        for (double control : ControlGrid(plan, direction)) {
          if (arm.elapsed_seconds >= options.time_budget_seconds) break;
          const bool frequency = plan.kind == SweepKind::kFrequency;
          TakeDwell(&rig, frequency ? control : plan.held_frequency_hz,
                    frequency ? plan.held_a_base : control, id, direction, plan.kind, &measured,
                    &arm);
          if (options.refit_dwells > 0 && ++in_sweep % options.refit_dwells == 0 &&
              Record(FitDwells(study, measured, estimate, options.target, &estimate, &basis),
                     &arm)) {
            break;
          }
        }
        if (arm.reached) break;
        if (Record(FitDwells(study, measured, estimate, options.target, &estimate, &basis), &arm))
          break;
        if (arm.elapsed_seconds >= options.time_budget_seconds) break;
      }
      if (arm.reached || arm.elapsed_seconds >= options.time_budget_seconds) break;
    }
  }
  arm.end = arm.reached ? "target met" : "time budget spent";
  JudgeCoverage(study, &arm);
  return arm;
}

namespace {

// The closed loop's start: the fitted sweeps of the plan, one direction
// each, at start_step_factor times their step.
void RunStart(const DesignStudyCase& study, const DesignStudyOptions& options,
              SweepDirection direction, VirtualRig* rig, Measured* measured, ArmRun* arm) {
  for (SweepPlan plan : study.plan.sweeps) {
    bool fitted = false;
    for (const SweepSelection& s : study.config.fit_sweeps) fitted |= s.sweep_id == plan.id;
    if (!fitted) continue;
    plan.step *= options.start_step_factor;
    const int n = static_cast<int>(std::floor((plan.to - plan.from) / plan.step + 1e-9));
    plan.to = plan.from + n * plan.step;
    rig->Rest();
    const bool frequency = plan.kind == SweepKind::kFrequency;
    for (double control : ControlGrid(plan, direction)) {
      TakeDwell(rig, frequency ? control : plan.held_frequency_hz,
                frequency ? plan.held_a_base : control,
                plan.id + (direction == SweepDirection::kUp ? "/start-up" : "/start-down"),
                direction, plan.kind, measured, arm);
    }
  }
}

// The rig's limits: the plan's frequency and level span, its smallest steps,
// the options' largest.
RigLimits PlanLimits(const DwellPlan& plan, const DesignStudyOptions& options) {
  RigLimits limits;
  limits.frequency_min_hz = limits.level_min = std::numeric_limits<double>::infinity();
  limits.frequency_step_min_hz = limits.level_step_min = std::numeric_limits<double>::infinity();
  for (const SweepPlan& s : plan.sweeps) {
    const bool f = s.kind == SweepKind::kFrequency;
    const double f_lo = f ? s.from : s.held_frequency_hz, f_hi = f ? s.to : s.held_frequency_hz;
    const double l_lo = f ? s.held_a_base : s.from, l_hi = f ? s.held_a_base : s.to;
    limits.frequency_min_hz = std::min(limits.frequency_min_hz, f_lo);
    limits.frequency_max_hz = std::max(limits.frequency_max_hz, f_hi);
    limits.level_min = std::min(limits.level_min, l_lo);
    limits.level_max = std::max(limits.level_max, l_hi);
    double& step_min = f ? limits.frequency_step_min_hz : limits.level_step_min;
    step_min = std::min(step_min, s.step);
  }
  if (!std::isfinite(limits.level_step_min)) limits.level_step_min = 0.1 * limits.level_min;
  if (!std::isfinite(limits.frequency_step_min_hz))
    limits.frequency_step_min_hz = 0.01 * limits.frequency_min_hz;
  limits.frequency_step_max_hz = options.frequency_step_max_hz > 0.0
                                     ? options.frequency_step_max_hz
                                     : limits.frequency_max_hz - limits.frequency_min_hz;
  limits.level_step_max =
      options.level_step_max > 0.0 ? options.level_step_max : limits.level_max - limits.level_min;
  return limits;
}

// The measured amplitude of the last dwell of `sweep`.
double LastAmplitude(const DesignStudyCase& study, const Measured& measured,
                     const std::string& sweep) {
  const ProcessedTraces one = ProcessTraces({measured.traces.at(sweep).back()}, study.processing);
  return one.sweeps.front().points.front().amplitude;
}

// The branch the rig is on after a dwell of measured amplitude `a`: where
// the estimate has two stable roots, the one nearer a (in ln a).
Branch BranchOf(ModelForm form, const ParameterVector& estimate, double f_hz, double level,
                double a) {
  const double omega = HzToRadPerSecond(f_hz);
  const StableRoot upper = ModelAmplitude(form, estimate, omega, level, Branch::kUpper, 0.0);
  const StableRoot lower = ModelAmplitude(form, estimate, omega, level, Branch::kLower, 0.0);
  if (upper.status != RootStatus::kOnBranch || lower.status != RootStatus::kOnBranch ||
      upper.branch == Branch::kOnly || !(upper.a > lower.a * (1.0 + 1e-9)) || !(a > 0.0)) {
    return Branch::kOnly;
  }
  return std::abs(std::log(a / upper.a)) < std::abs(std::log(a / lower.a)) ? Branch::kUpper
                                                                           : Branch::kLower;
}

DesignTarget TargetOf(int quantity) {
  DesignTarget target;
  if (quantity == kStudyAlphaE) {
    target.kind = TargetKind::kEffectiveNonlinearity;
  } else {
    target.kind = TargetKind::kParameter;
    target.parameter = quantity == kStudyEtaE    ? kEtaE
                       : quantity == kStudyOmega ? kNaturalFrequency
                                                 : kMu1;
  }
  return target;
}

// The best candidate that lands where the quasi-static rule can be trusted:
// single-valued, or within `steps` smallest steps of the present state.
const Candidate* SafeBest(const Recommendation& rec, const RigLimits& limits, int steps) {
  for (const Candidate& c : rec.ranked) {
    if (c.branch == Branch::kOnly) return &c;
    const double df = std::abs(c.frequency_hz - rec.state.frequency_hz);
    const double dl = std::abs(c.level - rec.state.level);
    if (df <= (steps + 0.5) * limits.frequency_step_min_hz &&
        dl <= (steps + 0.5) * limits.level_step_min) {
      return &c;
    }
  }
  return nullptr;
}

}  // namespace

ArmRun RunClosedLoop(const DesignStudyCase& study, const DesignStudyOptions& options,
                     std::uint64_t seed) {
  ArmRun arm{"closed_loop", seed};
  VirtualRig rig = MakeRig(study, seed);
  Measured measured;
  ParameterVector estimate = InitialGuess(study.config);
  DesignBasis basis;
  RunStart(study, options, SweepDirection::kUp, &rig, &measured, &arm);
  if (arm.dwells.empty()) {
    throw InputError(study.config.config_path, 0, "fit",
                     "none of the fitted sweeps is in the plan, so the closed loop has no start; "
                     "fit sweeps of the plan");
  }
  Record(FitDwells(study, measured, estimate, options.target, &estimate, &basis), &arm);
  if (!arm.fits.back().has_intervals) {
    RunStart(study, options, SweepDirection::kDown, &rig, &measured, &arm);
    Record(FitDwells(study, measured, estimate, options.target, &estimate, &basis), &arm);
  }
  const RigLimits limits = PlanLimits(study.plan, options);
  DesignOptions design;
  design.settle_time_constants = options.settle_time_constants;
  design.recording_seconds = study.rig.record_periods / limits.frequency_min_hz;
  const StudyDwell& last = arm.dwells.back();
  RigState state{last.frequency_hz, last.level, Branch::kOnly};
  const ModelForm form = study.config.identification.solve.residual.form;
  state.branch = BranchOf(form, estimate, state.frequency_hz, state.level,
                          LastAmplitude(study, measured, last.sweep));
  arm.end = "time budget spent";
  for (int n = 1; !arm.reached; ++n) {
    if (arm.elapsed_seconds >= options.time_budget_seconds) break;
    if (n > options.max_closed_loop_dwells) {
      arm.end = "dwell limit reached";
      break;
    }
    if (!arm.fits.empty() && !arm.fits.back().has_intervals && basis.noise_sigma == 0.0) {
      arm.end = "the start's fit gives no intervals";
      break;
    }
    int worst = 0;
    WorstRatio(arm.fits.back().has_intervals ? arm.fits.back() : StudyFit(), options.target,
               &worst);
    design.target = TargetOf(worst);
    const Recommendation rec = RecommendNextDwell(basis, state, limits, design);
    const Candidate* best = SafeBest(rec, limits, options.hysteresis_steps);
    if (best == nullptr) {
      arm.end = "no candidate within the limits";
      break;
    }
    const Candidate& next = *best;
    const std::string id = StringPrintf("N%d", n);
    TakeDwell(&rig, next.frequency_hz, next.level, id, SweepDirection::kUp, SweepKind::kFrequency,
              &measured, &arm);
    Record(FitDwells(study, measured, estimate, options.target, &estimate, &basis), &arm);
    state = {next.frequency_hz, next.level,
             BranchOf(form, estimate, next.frequency_hz, next.level,
                      LastAmplitude(study, measured, id))};
    arm.dwells.back().expected_branch = BranchName(next.branch);
    arm.dwells.back().landed_branch = BranchName(state.branch);
  }
  if (arm.reached) arm.end = "target met";
  JudgeCoverage(study, &arm);
  return arm;
}

DesignStudyResult RunDesignStudy(const DesignStudyCase& study, const DesignStudyOptions& options,
                                 std::ostream* progress) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("design_study options: " + error);
  DesignStudyResult result;
  result.case_name = study.name;
  DesignStudyCase fitted_as = study;
  if (options.averaging) {
    fitted_as.config.identification.solve.residual.form.averaging = *options.averaging;
  }
  for (int i = 0; i < options.seeds; ++i) {
    const std::uint64_t seed = options.first_seed + i;
    for (bool closed : {false, true}) {
      ArmRun arm = closed ? RunClosedLoop(fitted_as, options, seed)
                          : RunStandardProtocol(fitted_as, options, seed);
      if (progress) {
        *progress << StringPrintf("%s seed %llu %-11s: %s at %.0f s, %zu dwells, %zu fits\n",
                                  study.name.c_str(), static_cast<unsigned long long>(seed),
                                  arm.arm.c_str(), arm.end.c_str(), arm.elapsed_seconds,
                                  arm.dwells.size(), arm.fits.size())
                  << std::flush;
      }
      (closed ? result.closed_loop : result.standard).push_back(std::move(arm));
    }
  }
  return result;
}

double Median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace dwellfit
