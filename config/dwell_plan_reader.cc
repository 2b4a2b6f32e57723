#include "dwellfit/config/dwell_plan_reader.h"

#include <array>
#include <optional>
#include <vector>

#include "dwellfit/config/config_source.h"
#include "dwellfit/config/strict_yaml.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {
namespace {

// A key of a sweep block and what its value is, for "missing" messages.
struct PlanKey {
  const char* name;
  const char* meaning;
};

// The keys that set the grid of a sweep of `kind`: the held control, then
// from, to and step of the stepped one.
std::array<PlanKey, 4> GridKeys(SweepKind kind) {
  if (kind == SweepKind::kFrequency) {
    return {{{"a_base", "the base level held"},
             {"from_hz", "the first drive frequency [Hz]"},
             {"to_hz", "the last drive frequency [Hz]"},
             {"step_hz", "the drive frequency step [Hz]"}}};
  }
  return {{{"freq_hz", "the drive frequency held [Hz]"},
           {"a_base_from", "the first base level"},
           {"a_base_to", "the last base level"},
           {"a_base_step", "the base level step"}}};
}

// A non-empty list, given as a list (a single value is not taken for one);
// `expected` describes it in the error.
std::vector<ConfigValue> ReadNonEmptyList(const ConfigValue& value, const ConfigSource& source,
                                          const std::string& expected) {
  if (!value.node.IsSequence() || value.node.size() == 0) {
    throw source.Error(value.path, value.mark, "expected " + expected);
  }
  return ReadList(value, source);
}

// The `truth` block: all six parameters of `form`'s member, omega given in Hz.
ParameterVector ReadTruth(const ConfigValue& value, const ConfigSource& source, ModelForm form) {
  const auto names = ParameterNames(form);
  const StrictMap block(value, source,
                        {"eta_e", "mu1", names[kMu2], names[kDelta], "alpha", "omega_hz"});
  auto get = [&](const PlanKey& key) {
    return block.Required(key.name, std::string("add the true ") + key.meaning);
  };
  ParameterVector truth{};
  truth[kEtaE] = ReadPositive(get({"eta_e", "forcing effectiveness (> 0)"}), source);
  truth[kMu1] = ReadNonNegative(get({"mu1", "linear damping [1/s] (>= 0)"}), source);
  truth[kMu2] = ReadNonNegative(form.cubic_damping() ? get({"mu3", "cubic damping (>= 0)"})
                                                     : get({"mu2", "quadratic damping (>= 0)"}),
                                source);
  truth[kDelta] = ReadFiniteDouble(form.quintic_stiffness() ? get({"alpha5", "quintic stiffness"})
                                                            : get({"delta", "nonlinear inertia"}),
                                   source);
  truth[kAlpha] = ReadFiniteDouble(get({"alpha", "cubic stiffness"}), source);
  truth[kNaturalFrequency] = HzToRadPerSecond(
      ReadPositive(get({"omega_hz", "linear natural frequency [Hz] (> 0)"}), source));
  return truth;
}

// The kind a sweep block states, if it states a known one. It decides which
// keys the block allows, so it is looked at before the block is read; a
// missing or unknown kind is reported when the block is read.
std::optional<SweepKind> StatedKind(const YAML::Node& block) {
  if (!block.IsMap()) return std::nullopt;
  // A missing key gives an invalid node, which throws on all but IsDefined().
  const YAML::Node kind = block["kind"];
  if (!kind.IsDefined() || !kind.IsScalar()) return std::nullopt;
  for (SweepKind candidate : {SweepKind::kFrequency, SweepKind::kAmplitude}) {
    if (kind.Scalar() == SweepKindName(candidate)) return candidate;
  }
  return std::nullopt;
}

// A grid key of the other kind of sweep is reported as such, not as a typo.
void CheckNoGridKeyOfOtherKind(const ConfigValue& value, const ConfigSource& source, SweepKind kind,
                               const std::vector<std::string>& allowed) {
  const SweepKind other =
      kind == SweepKind::kFrequency ? SweepKind::kAmplitude : SweepKind::kFrequency;
  for (const auto& entry : value.node) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : "";
    for (const PlanKey& grid_key : GridKeys(other)) {
      if (key != grid_key.name) continue;
      throw source.Error(value.path + "." + key, entry.first.Mark(),
                         "'" + key + "' belongs to " + SweepKindName(other) +
                             " sweeps, and this sweep has kind " + SweepKindName(kind) +
                             "; allowed: " + JoinNames(allowed) +
                             " (or set kind: " + SweepKindName(other) + ")");
    }
  }
}

// One entry of `sweeps`; `id` is set to where its id was read.
SweepPlan ReadSweep(const ConfigValue& value, const ConfigSource& source, ConfigValue* id) {
  const std::optional<SweepKind> stated = StatedKind(value.node);
  std::vector<std::string> allowed = {"id", "kind", "directions", "start"};
  for (SweepKind kind : {SweepKind::kFrequency, SweepKind::kAmplitude}) {
    if (stated.has_value() && *stated != kind) continue;
    for (const PlanKey& key : GridKeys(kind)) allowed.push_back(key.name);
  }
  if (stated.has_value()) CheckNoGridKeyOfOtherKind(value, source, *stated, allowed);
  const StrictMap block(value, source, allowed);

  SweepPlan sweep;
  const std::vector<std::string> kinds = {SweepKindName(SweepKind::kFrequency),
                                          SweepKindName(SweepKind::kAmplitude)};
  const ConfigValue kind = block.Required(
      "kind",
      "add kind: frequency (drive frequency stepped, a_base held) or kind: amplitude "
      "(a_base stepped, drive frequency held)");
  sweep.kind = ReadOneOf(kind, source, "sweep kind", kinds) == kinds[0] ? SweepKind::kFrequency
                                                                        : SweepKind::kAmplitude;
  const std::string kind_name = SweepKindName(sweep.kind);
  *id = block.Required("id", "add id, the sweep's name in the CSV's sweep column (e.g. F0.01)");
  sweep.id = ReadNonEmptyString(*id, source);
  std::array<double, 4> grid{};
  const std::array<PlanKey, 4> grid_keys = GridKeys(sweep.kind);
  for (std::size_t i = 0; i < grid_keys.size(); ++i) {
    const std::string hint = std::string("add ") + grid_keys[i].name + " (" + grid_keys[i].meaning +
                             ") to this " + kind_name + " sweep";
    grid[i] = ReadPositive(block.Required(grid_keys[i].name, hint), source);
  }
  (sweep.kind == SweepKind::kFrequency ? sweep.held_a_base : sweep.held_frequency_hz) = grid[0];
  sweep.from = grid[1];
  sweep.to = grid[2];
  sweep.step = grid[3];
  if (const auto directions = block.Optional("directions")) {
    const std::vector<std::string> names = {SweepDirectionName(SweepDirection::kUp),
                                            SweepDirectionName(SweepDirection::kDown)};
    sweep.directions.clear();
    for (const ConfigValue& entry :
         ReadNonEmptyList(*directions, source, "a non-empty list such as [up, down]")) {
      SweepDirection direction;
      SweepDirectionFromName(ReadOneOf(entry, source, "direction", names), &direction);
      sweep.directions.push_back(direction);
    }
  }
  if (const auto start = block.Optional("start")) {
    const std::string branch = ReadOneOf(*start, source, "start branch", {"lower", "upper"});
    sweep.start_branch = branch == "lower" ? Branch::kLower : Branch::kUpper;
  }
  std::string error;
  if (!sweep.IsValid(&error)) throw source.Error(value.path, value.mark, error);
  return sweep;
}

// The `sweeps` list: one sweep or more, ids unique. Entries are named
// `sweeps[0]`, `sweeps[1]`, ... in errors.
std::vector<SweepPlan> ReadSweeps(const ConfigValue& value, const ConfigSource& source) {
  const std::vector<ConfigValue> entries = ReadNonEmptyList(
      value, source, "a list of one sweep or more, each a block of keys (- id: F0.01, ...)");
  std::vector<SweepPlan> sweeps;
  std::vector<ConfigValue> ids;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const ConfigValue entry{entries[i].node, value.path + "[" + std::to_string(i) + "]",
                            entries[i].mark};
    ConfigValue id;
    sweeps.push_back(ReadSweep(entry, source, &id));
    for (std::size_t j = 0; j + 1 < sweeps.size(); ++j) {
      if (sweeps[j].id != sweeps.back().id) continue;
      throw source.Error(id.path, id.mark,
                         "sweep id '" + sweeps.back().id + "' is used twice (first at " +
                             source.Where(ids[j].path, ids[j].mark) + "); ids must be unique");
    }
    ids.push_back(id);
  }
  return sweeps;
}

DwellNoise ReadNoise(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"relative_sigma", "seed"});
  DwellNoise noise;
  const ConfigValue sigma =
      block.Required("relative_sigma", "add relative_sigma, in [0, 1) (0: noise-free)");
  noise.relative_sigma = ReadNonNegative(sigma, source);
  if (!(noise.relative_sigma < 1.0)) {
    throw source.Error(
        sigma.path, sigma.mark,
        "must be below 1 (a relative standard deviation), got " + sigma.node.Scalar());
  }
  noise.seed = ReadUint64(
      block.Required("seed", "add seed, the std::mt19937_64 seed (a whole number >= 0)"), source);
  return noise;
}

DwellPlan ReadPlan(const ConfigSource& source) {
  const ConfigValue document = DocumentValue(source);
  const StrictMap block(document, source, {"truth", "sweeps", "noise", "model"});
  DwellPlan plan;
  if (const auto model = block.Optional("model")) plan.form = ReadModelForm(*model, source);
  plan.truth = ReadTruth(
      block.Required("truth", "add truth: with eta_e, mu1, mu2, delta, alpha and omega_hz"), source,
      plan.form);
  plan.sweeps =
      ReadSweeps(block.Required("sweeps", "add sweeps: a list of one sweep or more"), source);
  if (const auto noise = block.Optional("noise")) plan.noise = ReadNoise(*noise, source);
  std::string error;
  if (!plan.IsValid(&error)) throw source.Error(document.path, document.mark, error);
  return plan;
}

}  // namespace

ModelForm ReadModelForm(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"averaging", "damping", "backbone"});
  ModelForm form;
  if (const auto averaging = block.Optional("averaging")) {
    AveragingFromName(
        ReadOneOf(*averaging, source, "averaging",
                  {AveragingName(Averaging::kFirstOrder), AveragingName(Averaging::kSecondOrder)}),
        &form.averaging);
  }
  if (const auto damping = block.Optional("damping")) {
    const std::string cubic = DampingTermName(DampingTerm::kCubic);
    if (ReadOneOf(*damping, source, "damping", {DampingTermName(DampingTerm::kQuadratic), cubic}) ==
        cubic) {
      form.damping = DampingTerm::kCubic;
    }
  }
  if (const auto backbone = block.Optional("backbone")) {
    const std::string quintic = BackboneTermName(BackboneTerm::kQuintic);
    if (ReadOneOf(*backbone, source, "backbone",
                  {BackboneTermName(BackboneTerm::kInertia), quintic}) == quintic) {
      form.backbone = BackboneTerm::kQuintic;
    }
  }
  if (form.second_order() && form.family_terms()) {
    throw source.Error(value.path, value.mark,
                       "averaging: second_order is derived for the chapter's terms only; give "
                       "averaging: first_order with damping: cubic or backbone: quintic, or drop "
                       "those keys for the second order");
  }
  if (!block.Optional("averaging") && !block.Optional("damping") && !block.Optional("backbone")) {
    throw source.Error(value.path, value.mark,
                       "names no model; give averaging: first_order | second_order, damping: "
                       "quadratic | cubic or backbone: inertia | quintic");
  }
  return form;
}

DwellPlan ParseDwellPlan(const std::string& yaml_text, const std::string& source) {
  return ReadPlan(ConfigSource::Parse(source, yaml_text));
}

DwellPlan ReadDwellPlan(const std::string& path) {
  return ReadPlan(ConfigSource::Load(path, "plan file"));
}

}  // namespace dwellfit
