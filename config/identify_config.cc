#include "dwellfit/config/identify_config.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>

#include "dwellfit/config/config_source.h"
#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/strict_yaml.h"
#include "dwellfit/estimator/data/sweep_csv.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;

struct PlacedSelection {
  SweepSelection selection;
  ConfigValue value;
};

// How a relative path in `value` is resolved: from the config file's
// directory, or from the working directory when an override gave it.
fs::path ResolvePath(const std::string& text, const ConfigValue& value, const ConfigSource& source,
                     const fs::path& config_dir) {
  fs::path path(text);
  if (path.is_relative()) {
    path = (source.OverrideFor(value.path) != nullptr ? fs::current_path() : config_dir) / path;
  }
  return path.lexically_normal();
}

// `hz` in rad/s. A frequency so large that it overflows there is an error
// at `value` (the reader has checked that `hz` is finite).
double RadPerSecond(double hz, const ConfigValue& value, const ConfigSource& source) {
  const double rad_s = HzToRadPerSecond(hz);
  if (!std::isfinite(rad_s)) {
    std::ostringstream text;
    text << hz;
    throw source.Error(value.path, value.mark,
                       "the frequency " + text.str() + " Hz is too large (infinite in rad/s)");
  }
  return rad_s;
}

std::vector<std::string> ReadDataFiles(const ConfigValue& value, const ConfigSource& source,
                                       const fs::path& config_dir) {
  const std::vector<ConfigValue> entries = ReadList(value, source);
  if (entries.empty()) {
    throw source.Error(value.path, value.mark,
                       "lists no data file; give a CSV path or a list of paths");
  }
  std::vector<std::string> files;
  std::vector<ConfigValue> places;
  for (const ConfigValue& entry : entries) {
    const std::string text = ReadNonEmptyString(entry, source);
    const std::string resolved = ResolvePath(text, entry, source, config_dir).string();
    std::error_code error;
    const std::string not_a_file = NotARegularFile(resolved);
    if (!not_a_file.empty()) {
      throw source.Error(entry.path, entry.mark,
                         "data file '" + text + "' at " + resolved + " " + not_a_file +
                             "; give the path of a sweeps CSV file");
    }
    if (!fs::is_regular_file(resolved, error)) {
      throw source.Error(entry.path, entry.mark,
                         "data file '" + text + "' not found at " + resolved +
                             (source.OverrideFor(entry.path) != nullptr
                                  ? " (a relative path given on the command line is relative to "
                                    "the working directory)"
                                  : " (a relative path in the config is relative to the config "
                                    "file's directory)"));
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
      if (files[i] == resolved) {
        throw source.Error(entry.path, entry.mark,
                           "data file " + resolved + " is listed twice (first at " +
                               source.Where(places[i].path, places[i].mark) +
                               "); its sweeps would be counted twice, keep one");
      }
    }
    files.push_back(resolved);
    places.push_back(entry);
  }
  return files;
}

// The sweeps of `fit` or `validate`; none may be selected twice.
std::vector<PlacedSelection> ReadSweepSelections(const ConfigValue& value,
                                                 const ConfigSource& source) {
  std::vector<PlacedSelection> placed;
  for (const ConfigValue& entry : ReadList(value, source)) {
    SweepSelection selection;
    std::string error;
    if (!ParseSweepSelection(ReadNonEmptyString(entry, source), &selection, &error)) {
      throw source.Error(entry.path, entry.mark, error);
    }
    for (const PlacedSelection& earlier : placed) {
      if (earlier.selection.Overlaps(selection)) {
        const std::string first =
            " (first at " + source.Where(earlier.value.path, earlier.value.mark) + ")";
        throw source.Error(
            entry.path, entry.mark,
            earlier.selection.Name() == selection.Name()
                ? "sweep '" + selection.Name() + "' is listed twice" + first + "; keep one"
                : "sweep '" + selection.Name() + "' overlaps '" + earlier.selection.Name() + "'" +
                      first + "; a sweep id alone selects both directions, so list either '" +
                      selection.sweep_id + "' or its directions");
      }
    }
    placed.push_back(PlacedSelection{selection, entry});
  }
  return placed;
}

std::vector<SweepSelection> Selections(const std::vector<PlacedSelection>& placed) {
  std::vector<SweepSelection> selections;
  for (const PlacedSelection& p : placed) selections.push_back(p.selection);
  return selections;
}

void CheckNoSweepFittedAndValidated(const std::vector<PlacedSelection>& fit,
                                    const std::vector<PlacedSelection>& validate,
                                    const ConfigSource& source) {
  for (const PlacedSelection& validated : validate) {
    for (const PlacedSelection& fitted : fit) {
      if (fitted.selection.Overlaps(validated.selection)) {
        throw source.Error(validated.value.path, validated.value.mark,
                           "sweep '" + validated.selection.Name() + "' is also fitted ('" +
                               fitted.selection.Name() + "' in 'fit' at " +
                               source.Where(fitted.value.path, fitted.value.mark) +
                               "); a validation sweep must not be fitted, remove it from one "
                               "of the lists");
      }
    }
  }
}

// The initial_guess block: `auto`, or per parameter a number (physical
// units, omega in Hz) or `auto`; a parameter left out is `auto`.
KnownParameters ReadInitialGuess(const ConfigValue& value, const ConfigSource& source,
                                 ModelForm form) {
  KnownParameters known;
  if (value.node.IsScalar() && value.node.Scalar() == "auto") return known;
  const auto member_names = ParameterNames(form);
  std::vector<std::string> names(member_names.begin(), member_names.end());
  names[kNaturalFrequency] = "omega_hz";
  const StrictMap block(value, source, names);
  for (int index = 0; index < kNumParameters; ++index) {
    const auto entry = block.Optional(names[index]);
    if (!entry || (entry->node.IsScalar() && entry->node.Scalar() == "auto")) continue;
    const double number = ReadFiniteDouble(*entry, source);
    const bool must_be_positive = index == kEtaE || index == kNaturalFrequency;
    const bool must_be_non_negative = index == kMu1 || index == kMu2;
    if (must_be_positive && !(number > 0.0)) {
      throw source.Error(entry->path, entry->mark,
                         std::string("the initial guess (") +
                             (index == kEtaE ? "forcing effectiveness, > 0"
                                             : "linear natural frequency [Hz], > 0") +
                             ") must be positive, got " + entry->node.Scalar() +
                             "; or write auto to find it from the data");
    }
    if (must_be_non_negative && number < 0.0) {
      throw source.Error(entry->path, entry->mark,
                         "the initial guess must be non-negative (the parameter is bounded "
                         "below by 0), got " +
                             entry->node.Scalar());
    }
    known[index] = index == kNaturalFrequency ? HzToRadPerSecond(number) : number;
  }
  return known;
}

// Placeholders for the guesses to be found from the data, so that the
// options validate before the data are read.
ParameterVector WithPlaceholders(const KnownParameters& known) {
  ParameterVector initial = {1.0, 0.0, 0.0, 0.0, 0.0, 1.0};
  for (int i = 0; i < kNumParameters; ++i) {
    if (known[i]) initial[i] = *known[i];
  }
  return initial;
}

// Throws the IsValid `message` of options read from `block`, at the block's
// line, naming the overrides that changed values inside it.
void ThrowInvalidBlock(const ConfigValue& block, const ConfigSource& source,
                       const std::string& message) {
  std::string set_by;
  for (const ConfigOverride* applied : source.OverridesWithin(block.path)) {
    set_by += (set_by.empty() ? "" : ", ") + DescribeOverride(*applied);
  }
  std::string what = message;
  if (!set_by.empty()) what += " (values set on the command line: " + set_by + ")";
  throw source.Error(block.path, block.mark, what);
}

// The options of the block `key` of `parent`, read by `read` (the defaults
// when absent), reported by ThrowInvalidBlock unless valid.
template <typename Options>
Options ReadValid(const StrictMap& parent, const std::string& key, const ConfigSource& source,
                  Options (*read)(const ConfigValue&, const ConfigSource&)) {
  const std::optional<ConfigValue> value = parent.Optional(key);
  const Options options = value ? read(*value, source) : Options();
  std::string message;
  if (!options.IsValid(&message)) {
    ThrowInvalidBlock(value ? *value : parent.block(), source, message);
  }
  return options;
}

MultiStartOptions ReadMultiStart(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"starts", "spread", "seed", "threads"});
  MultiStartOptions multi_start;
  block.Read("starts", &multi_start.starts);
  block.Read("spread", &multi_start.spread);
  if (const auto v = block.Optional("seed")) multi_start.seed = ReadUint64(*v, source);
  block.Read("threads", &multi_start.threads);
  return multi_start;
}

// An error about one entry of a list: named by the flag that added it
// (--fix), else by its line or the override that set the list.
InputError EntryError(const ConfigValue& entry, const ConfigSource& source,
                      const std::string& what) {
  if (const ConfigOverride* added = source.AddedBy(entry.node)) {
    return InputError(added->origin, 0, entry.path, what);
  }
  return source.Error(entry.path, entry.mark, what);
}

// The `fixed` list. A fixed parameter is held at the value the config gives,
// so it must have one in `known` (initial_guess): the automatic value is a
// rough start, not a value to hold.
std::array<bool, kNumParameters> ReadFixed(const ConfigValue& value, const ConfigSource& source,
                                           const KnownParameters& known, ModelForm form) {
  const auto names = ParameterNames(form);
  const std::vector<std::string> allowed(names.begin(), names.end());
  std::array<bool, kNumParameters> fixed{};
  for (const ConfigValue& entry : ReadList(value, source)) {
    const std::string name = ReadNonEmptyString(entry, source);
    ParameterIndex index;
    if (!ParameterIndexFromName(form, name, &index)) {
      const std::string hint =
          name == "omega_hz" ? " (the parameter is called 'omega')" : DidYouMean(name, allowed);
      throw EntryError(entry, source,
                       "unknown parameter '" + EscapeForMessage(name) + "'" + hint +
                           "; allowed: " + JoinNames(allowed));
    }
    if (fixed[index]) {
      throw EntryError(entry, source, "parameter '" + name + "' is listed twice; keep one");
    }
    if (!known[index]) {
      const std::string key = index == kNaturalFrequency ? "omega_hz" : name;
      throw EntryError(entry, source,
                       "parameter '" + name +
                           "' is fixed but has no initial guess, and a fixed parameter is held "
                           "at the value the config gives: add initial_guess." +
                           key + " (on the command line: --set initial_guess." + key +
                           "=VALUE), or do not fix '" + name + "'");
    }
    fixed[index] = true;
  }
  return fixed;
}

std::vector<ResidualKind> ReadStages(const ConfigValue& value, const ConfigSource& source) {
  const std::vector<std::string> allowed = {
      ResidualKindName(ResidualKind::kAlgebraic), ResidualKindName(ResidualKind::kVertical),
      ResidualKindName(ResidualKind::kPhaseLag), ResidualKindName(ResidualKind::kAllRoots)};
  std::vector<ResidualKind> stages;
  for (const ConfigValue& entry : ReadList(value, source)) {
    ResidualKindFromName(ReadOneOf(entry, source, "stage", allowed), &stages.emplace_back());
  }
  if (stages.empty()) {
    throw source.Error(value.path, value.mark,
                       "lists no stage; give at least one of " + JoinNames(allowed) +
                           ", or remove the key for the default [algebraic, vertical]");
  }
  return stages;
}

ResidualOptions ReadResidual(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"error", "use_point_sigma", "amplitude_floor"});
  ResidualOptions residual;
  if (const auto error = block.Optional("error")) {
    const std::vector<std::string> allowed = {ErrorMeasureName(ErrorMeasure::kAbsolute),
                                              ErrorMeasureName(ErrorMeasure::kRelative)};
    ErrorMeasureFromName(ReadOneOf(*error, source, "error measure", allowed), &residual.error);
  }
  block.Read("use_point_sigma", &residual.use_point_sigma);
  if (const auto floor = block.Optional("amplitude_floor")) {
    residual.amplitude_floor = ReadFiniteDouble(*floor, source);
    if (residual.amplitude_floor < 0.0) {
      throw source.Error(floor->path, floor->mark,
                         "must be >= 0 (the noise floor of the measured amplitude, in its unit)");
    }
  }
  return residual;
}

SolverSettings ReadSolver(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(
      value, source,
      {"max_iterations", "function_tolerance", "start_function_tolerance", "gradient_tolerance",
       "parameter_tolerance", "num_threads", "nonmonotonic_steps", "valley_polish"});
  SolverSettings solver;
  block.Read("max_iterations", &solver.max_iterations);
  block.Read("function_tolerance", &solver.function_tolerance);
  block.Read("start_function_tolerance", &solver.start_function_tolerance);
  block.Read("gradient_tolerance", &solver.gradient_tolerance);
  block.Read("parameter_tolerance", &solver.parameter_tolerance);
  block.Read("valley_polish", &solver.valley_polish);
  block.Read("nonmonotonic_steps", &solver.nonmonotonic_steps);
  block.Read("num_threads", &solver.num_threads);
  return solver;
}

JumpDetectionOptions ReadJumpDetection(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(
      value, source,
      {"min_ratio", "min_relative_amplitude", "noise_multiple", "min_candidate_steps"});
  JumpDetectionOptions jump_detection;
  block.Read("min_ratio", &jump_detection.min_ratio);
  block.Read("min_relative_amplitude", &jump_detection.min_relative_amplitude);
  block.Read("noise_multiple", &jump_detection.noise_multiple);
  block.Read("min_candidate_steps", &jump_detection.min_candidate_steps);
  return jump_detection;
}

// One jump override's bracket: two positive, different numbers.
std::pair<double, double> ReadBracket(const ConfigValue& value, const ConfigSource& source) {
  const std::vector<ConfigValue> ends = ReadList(value, source);
  if (ends.size() != 2 || !value.node.IsSequence()) {
    throw source.Error(value.path, value.mark,
                       "expected two values, [before, after] in measurement order, got " +
                           std::to_string(value.node.IsSequence() ? ends.size() : 1));
  }
  const double before = ReadFiniteDouble(ends[0], source);
  const double after = ReadFiniteDouble(ends[1], source);
  if (!(before > 0.0) || !(after > 0.0)) {
    throw source.Error(value.path, value.mark, "the bracket's values must be positive");
  }
  if (before == after) {
    throw source.Error(value.path, value.mark,
                       "the bracket's two values are equal; give the controls of the last dwell "
                       "before the jump and the first after it");
  }
  return {before, after};
}

// The last key of a key path: "between_hz" of "jumps[0].between_hz".
std::string LastKey(const std::string& path) { return path.substr(path.rfind('.') + 1); }

// The `sweep` of a jump entry: one direction of one sweep.
std::string ReadJumpSweep(const StrictMap& block, const ConfigSource& source) {
  const ConfigValue sweep =
      block.Required("sweep", "name the sweep and one direction, e.g. sweep: L0.060g/down");
  SweepSelection selection;
  std::string error;
  if (!ParseSweepSelection(ReadNonEmptyString(sweep, source), &selection, &error)) {
    throw source.Error(sweep.path, sweep.mark, error);
  }
  if (!selection.direction.has_value()) {
    const std::string& id = selection.sweep_id;
    throw source.Error(sweep.path, sweep.mark,
                       "'" + id + "' names both directions; a jump belongs to one: write '" + id +
                           "/up' or '" + id + "/down'");
  }
  return selection.Name();
}

// One entry of `jumps`: a sweep and exactly one of between_hz, between_a_base
// (each with a kind) or none: true.
JumpOverride ReadJumpOverride(const ConfigValue& entry, const ConfigSource& source) {
  const StrictMap block(entry, source, {"sweep", "kind", "between_hz", "between_a_base", "none"});
  JumpOverride jump;
  jump.field = entry.path;
  const bool from_file = source.OverrideFor(entry.path) == nullptr && !entry.mark.is_null();
  jump.line = from_file ? entry.mark.line + 1 : 0;
  jump.sweep = ReadJumpSweep(block, source);

  std::optional<ConfigValue> statement;
  for (const char* key : {"between_hz", "between_a_base", "none"}) {
    const std::optional<ConfigValue> value = block.Optional(key);
    if (!value.has_value()) continue;
    if (statement.has_value()) {
      throw source.Error(value->path, value->mark,
                         "give exactly one of between_hz, between_a_base and none (this entry "
                         "also has '" +
                             LastKey(statement->path) + "')");
    }
    statement = value;
  }
  if (!statement.has_value()) {
    throw source.Error(entry.path, entry.mark,
                       "give exactly one of between_hz: [before, after] (frequency sweep), "
                       "between_a_base: [before, after] (amplitude sweep) or none: true");
  }
  const std::optional<ConfigValue> kind = block.Optional("kind");
  const std::string key = LastKey(statement->path);
  if (key == "none") {
    if (!ReadBool(*statement, source)) {
      throw source.Error(statement->path, statement->mark,
                         "none: false states nothing; write none: true for a sweep without a "
                         "jump, or give kind and between_hz (or between_a_base)");
    }
    if (kind.has_value()) {
      throw source.Error(kind->path, kind->mark,
                         "a sweep with none: true has no jump, so no kind; remove one of them");
    }
    jump.none = true;
    return jump;
  }

  if (!kind.has_value()) {
    throw source.Error(
        entry.path + ".kind", entry.mark,
        "missing required key 'kind' in '" + entry.path + "'; give jump_up or jump_down");
  }
  const std::vector<std::string> kinds = {JumpKindName(JumpKind::kJumpUp),
                                          JumpKindName(JumpKind::kJumpDown)};
  jump.kind = ReadOneOf(*kind, source, "jump kind", kinds) == kinds[0] ? JumpKind::kJumpUp
                                                                       : JumpKind::kJumpDown;
  const auto [before, after] = ReadBracket(*statement, source);
  const bool frequency = key == "between_hz";
  jump.control = frequency ? SweepKind::kFrequency : SweepKind::kAmplitude;
  jump.control_before = frequency ? RadPerSecond(before, *statement, source) : before;
  jump.control_after = frequency ? RadPerSecond(after, *statement, source) : after;
  return jump;
}

// The `jumps` list: at most one entry per sweep.
std::vector<JumpOverride> ReadJumpOverrides(const ConfigValue& value, const ConfigSource& source) {
  std::vector<JumpOverride> jumps;
  std::vector<ConfigValue> places;
  const std::vector<ConfigValue> entries = ReadList(value, source);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const ConfigValue entry{entries[i].node, value.path + "[" + std::to_string(i) + "]",
                            entries[i].mark};
    JumpOverride jump = ReadJumpOverride(entry, source);
    for (std::size_t j = 0; j < jumps.size(); ++j) {
      if (jumps[j].sweep == jump.sweep) {
        throw source.Error(entry.path, entry.mark,
                           "sweep '" + jump.sweep + "' has a jump entry already (at " +
                               source.Where(places[j].path, places[j].mark) + "); keep one");
      }
    }
    jumps.push_back(jump);
    places.push_back(entry);
  }
  return jumps;
}

std::vector<JumpTarget> ReadJumpTargets(const ConfigValue& value, const ConfigSource& source) {
  std::vector<std::string> allowed;
  for (JumpTarget target : {JumpTarget::kFrequencyJumpUp, JumpTarget::kFrequencyJumpDown,
                            JumpTarget::kAmplitudeJumpUp, JumpTarget::kAmplitudeJumpDown}) {
    allowed.push_back(JumpTargetName(target));
  }
  std::vector<JumpTarget> targets;
  for (const ConfigValue& entry : ReadList(value, source)) {
    const std::string name = ReadOneOf(entry, source, "jump", allowed);
    JumpTarget target;
    JumpTargetFromName(name, &target);
    if (std::find(targets.begin(), targets.end(), target) != targets.end()) {
      throw source.Error(entry.path, entry.mark, "jump '" + name + "' is listed twice; keep one");
    }
    targets.push_back(target);
  }
  return targets;
}

BifurcationRangeOptions ReadBifurcationRange(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"enabled", "exponent", "weight", "enforce"});
  BifurcationRangeOptions range;
  block.Read("enabled", &range.enabled);
  block.Read("exponent", &range.exponent);
  block.Read("weight", &range.weight);
  if (const auto v = block.Optional("enforce")) range.enforce = ReadJumpTargets(*v, source);
  return range;
}

BranchStabilityOptions ReadBranchStability(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"enabled", "lambda", "weight"});
  BranchStabilityOptions stability;
  block.Read("enabled", &stability.enabled);
  block.Read("lambda", &stability.lambda);
  block.Read("weight", &stability.weight);
  return stability;
}

// The `penalties` block; each sub-block's IsValid is reported at its line.
PenaltyOptions ReadPenalties(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"bifurcation_range", "branch_stability"});
  PenaltyOptions penalties;
  penalties.bifurcation_range = ReadValid(block, "bifurcation_range", source, ReadBifurcationRange);
  penalties.branch_stability = ReadValid(block, "branch_stability", source, ReadBranchStability);
  return penalties;
}

// The `forcing_calibration` block (fit/forcing_calibration.h); its IsValid
// is reported at its line.
ForcingCalibrationOptions ReadForcingCalibration(const ConfigValue& value,
                                                 const ConfigSource& source) {
  const StrictMap block(value, source, {"prior_sigma", "held_out_dwells", "parameter"});
  ForcingCalibrationOptions calibration;
  block.Read("prior_sigma", &calibration.prior_sigma);
  if (const auto dwells = block.Optional("held_out_dwells")) {
    if (!HeldOutDwellsFromName(ReadNonEmptyString(*dwells, source), &calibration.held_out_dwells)) {
      throw source.Error(dwells->path, dwells->mark, "give before_jump or below_half_peak");
    }
  }
  if (const auto parameter = block.Optional("parameter")) {
    if (!CalibratedParameterFromName(ReadNonEmptyString(*parameter, source),
                                     &calibration.parameter)) {
      throw source.Error(parameter->path, parameter->mark,
                         "give eta_e (the forcing) or omega (the natural frequency)");
    }
  }
  return calibration;
}

// `excitation:`, `response:` and `phase:`: the test as run. A relative
// error with a floor is refused for a velocity or acceleration response
// (ResidualOptions::IsValid), at the `response` key.
void ReadTestQuantities(const StrictMap& top, const ConfigSource& source, IdentifyConfig* config) {
  TestQuantities& test = config->test;
  if (const auto value = top.Optional("excitation")) {
    ExcitationFromName(ReadOneOf(*value, source, "excitation",
                                 {ExcitationName(Excitation::kBaseAcceleration),
                                  ExcitationName(Excitation::kBaseDisplacement),
                                  ExcitationName(Excitation::kForce)}),
                       &test.excitation);
  }
  if (const auto value = top.Optional("response")) {
    ResponseFromName(
        ReadOneOf(*value, source, "response",
                  {ResponseName(Response::kDisplacement), ResponseName(Response::kVelocity),
                   ResponseName(Response::kAcceleration)}),
        &test.response);
    ResidualOptions& residual = config->identification.solve.residual;
    residual.response_power = test.ResponsePower();
    std::string message;
    if (!residual.IsValid(&message)) throw source.Error(value->path, value->mark, message);
  }
  if (const auto value = top.Optional("phase")) {
    const StrictMap block(*value, source, {"offset_deg", "offset"});
    const auto degrees = block.Optional("offset_deg");
    const auto estimate = block.Optional("offset");
    if (degrees && estimate) {
      throw source.Error(estimate->path, estimate->mark,
                         "give either offset_deg (a stated offset) or offset: estimate, not both");
    }
    if (degrees) test.phase_offset_rad = ReadFiniteDouble(*degrees, source) * kPi / 180.0;
    if (estimate) {
      ReadOneOf(*estimate, source, "phase offset", {"estimate"});
      test.estimate_phase_offset = true;
    }
    if (!degrees && !estimate) {
      throw source.Error(value->path, value->mark,
                         "states no offset; give offset_deg: X (the phase column minus the "
                         "measured quantity's lag, in degrees) or offset: estimate");
    }
  }
}

// `model: {averaging: ..., damping: ..., backbone: ...}`: the response model
// every stage evaluates (model_form.h); the chapter's where the key is absent.
ModelForm ReadModel(const StrictMap& top, const ConfigSource& source) {
  if (const auto value = top.Optional("model")) return ReadModelForm(*value, source);
  return ModelForm{};
}

// `units:` and `plot:`: how figures and reports show the data.
void ReadPresentation(const StrictMap& top, const ConfigSource& source, IdentifyConfig* config) {
  if (const auto value = top.Optional("units")) {
    const StrictMap units(*value, source, {"a", "a_base"});
    if (const auto a = units.Optional("a")) config->units.a = ReadNonEmptyString(*a, source);
    if (const auto base = units.Optional("a_base")) {
      config->units.a_base = ReadNonEmptyString(*base, source);
    }
  }
  if (const auto value = top.Optional("plot")) {
    StrictMap(*value, source, {"log_amplitude"}).Read("log_amplitude", &config->log_amplitude);
  }
  if (const auto value = top.Optional("outputs")) {
    StrictMap(*value, source, {"mat"}).Read("mat", &config->write_mat);
  }
}

// The top-level keys; the last three describe the test as run.
std::vector<std::string> TopLevelKeys() {
  return {"data",
          "fit",
          "validate",
          "initial_guess",
          "fixed",
          "stages",
          "model",
          "residual",
          "solver",
          "penalties",
          "multi_start",
          "jump_detection",
          "jumps",
          "effective_nonlinearity_reference_hz",
          "model_selection",
          "forcing_calibration",
          "output_dir",
          "units",
          "plot",
          "outputs",
          "excitation",
          "response",
          "phase"};
}

IdentifyConfig ReadIdentifyConfig(const ConfigSource& source, const fs::path& config_dir) {
  const StrictMap top(DocumentValue(source), source, TopLevelKeys());
  IdentifyConfig config;
  config.data_files =
      ReadDataFiles(top.Required("data", "give the sweeps file, CSV or .mat (or a list of files)"),
                    source, config_dir);

  const ConfigValue fit_value =
      top.Required("fit", "list the sweep ids to fit, e.g. fit: [F0.01, A41.5/up]");
  const std::vector<PlacedSelection> fit = ReadSweepSelections(fit_value, source);
  if (fit.empty()) {
    throw source.Error(fit_value.path, fit_value.mark,
                       "lists no sweep; give at least one sweep id to fit");
  }
  std::vector<PlacedSelection> validate;
  if (const auto value = top.Optional("validate")) validate = ReadSweepSelections(*value, source);
  CheckNoSweepFittedAndValidated(fit, validate, source);
  config.fit_sweeps = Selections(fit);
  config.validate_sweeps = Selections(validate);

  IdentificationOptions& identification = config.identification;
  // The model names the parameters the keys below hold.
  const ModelForm form = ReadModel(top, source);
  if (const auto value = top.Optional("initial_guess")) {
    config.initial_guess = ReadInitialGuess(*value, source, form);
  }
  identification.initial = WithPlaceholders(config.initial_guess);
  if (const auto value = top.Optional("fixed")) {
    identification.fixed = ReadFixed(*value, source, config.initial_guess, form);
  }
  if (const auto value = top.Optional("stages"))
    identification.solve.stages = ReadStages(*value, source);
  if (const auto value = top.Optional("residual")) {
    identification.solve.residual = ReadResidual(*value, source);
  }
  identification.solve.solver = ReadValid(top, "solver", source, ReadSolver);
  if (const auto value = top.Optional("penalties")) {
    identification.solve.penalties = ReadPenalties(*value, source);
  }

  if (const auto value = top.Optional("model_selection")) {
    config.model_selection = ReadModelSelectionConfig(*value, source, config.initial_guess);
  }
  if (top.Optional("forcing_calibration")) {
    config.forcing_calibration =
        ReadValid(top, "forcing_calibration", source, ReadForcingCalibration);
  }
  config.multi_start = ReadValid(top, "multi_start", source, ReadMultiStart);
  config.jump_detection = ReadValid(top, "jump_detection", source, ReadJumpDetection);
  if (const auto value = top.Optional("jumps")) {
    config.jump_overrides = ReadJumpOverrides(*value, source);
  }

  if (const auto value = top.Optional("effective_nonlinearity_reference_hz")) {
    const double hz = ReadFiniteDouble(*value, source);
    if (!(hz > 0.0)) {
      throw source.Error(value->path, value->mark,
                         "must be a positive frequency in Hz, got " + value->node.Scalar() +
                             "; remove the key to use the identified natural frequency");
    }
    config.omega_ref_rad_s = RadPerSecond(hz, *value, source);
  }

  ReadTestQuantities(top, source, &config);
  identification.solve.residual.form = form;  // after `residual:`, whose block it joins
  ReadPresentation(top, source, &config);
  const ConfigValue output_dir =
      top.Required("output_dir", "give the directory for the results, e.g. output_dir: out");
  config.output_dir =
      ResolvePath(ReadNonEmptyString(output_dir, source), output_dir, source, config_dir).string();
  return config;
}

IdentifyConfig ReadSource(ConfigSource source, const std::string& name, const fs::path& config_path,
                          const std::vector<ConfigOverride>& overrides) {
  source.Apply(overrides);
  IdentifyConfig config;
  try {
    config = ReadIdentifyConfig(source, config_path.parent_path());
  } catch (const YAML::Exception& e) {
    // The readers check types before converting; this is a safety net.
    throw InputError(name, e.mark.is_null() ? 0 : e.mark.line + 1, "", e.what());
  }
  config.config_path = config_path.string();
  config.overrides = overrides;
  return config;
}

}  // namespace

DataUnits ModelFormUnits(const DataUnits& units, const TestQuantities& test) {
  const int p = test.ResponsePower();
  DataUnits model;
  const char* unstated[] = {"[A]", "[V]", "[Acc]"};
  const std::string a = units.a.empty() ? unstated[p] : units.a;
  const std::string time = p == 1 ? "/s" : "/s^2";
  if (p == 0) {
    model.a = a;
  } else if (a.size() > time.size() && a.compare(a.size() - time.size(), time.size(), time) == 0) {
    model.a = a.substr(0, a.size() - time.size());  // m/s -> m
  } else {
    model.a = "(" + a + (p == 1 ? " s)" : " s^2)");
  }
  const std::string b = units.a_base.empty() ? "[B]" : units.a_base;
  model.a_base = test.LevelPower() == 0 ? b : b + "/s^2";
  return model;
}

IdentifyConfig LoadIdentifyConfig(const std::string& path,
                                  const std::vector<ConfigOverride>& overrides) {
  return ReadSource(ConfigSource::Load(path), path, fs::absolute(path).lexically_normal(),
                    overrides);
}

IdentifyConfig ParseIdentifyConfig(const std::string& name, const std::string& yaml_text,
                                   const std::string& base_dir,
                                   const std::vector<ConfigOverride>& overrides) {
  return ReadSource(ConfigSource::Parse(name, yaml_text), name,
                    (fs::absolute(base_dir) / name).lexically_normal(), overrides);
}

}  // namespace dwellfit
