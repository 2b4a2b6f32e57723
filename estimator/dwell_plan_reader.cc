#include "estimator/dwell_plan_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "estimator/input_error.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

std::string JoinKeys(const std::vector<std::string>& keys) {
  std::string joined;
  for (const std::string& key : keys) joined += (joined.empty() ? "" : ", ") + key;
  return joined;
}

class PlanParser {
 public:
  explicit PlanParser(std::string source) : source_(std::move(source)) {}

  DwellPlan Parse(const YAML::Node& root) {
    if (!root.IsMap()) {
      Fail(root, "", "the plan must be a mapping with keys truth, sweeps and (optional) noise");
    }
    CheckKeys(root, "", {"truth", "sweeps", "noise"});
    DwellPlan plan;
    plan.truth = Truth(Required(root, "truth", ""));
    const YAML::Node sweeps = Required(root, "sweeps", "");
    if (!sweeps.IsSequence() || sweeps.size() == 0) {
      Fail(sweeps, "sweeps", "must be a non-empty list of sweeps");
    }
    std::set<std::string> ids;
    for (std::size_t i = 0; i < sweeps.size(); ++i) {
      const std::string section = "sweeps[" + std::to_string(i) + "]";
      plan.sweeps.push_back(Sweep(sweeps[i], section));
      if (!ids.insert(plan.sweeps.back().id).second) {
        Fail(sweeps[i]["id"], section + ".id",
             "sweep id '" + plan.sweeps.back().id + "' is used twice; ids must be unique");
      }
    }
    if (root["noise"]) plan.noise = Noise(root["noise"]);
    std::string error;
    if (!plan.IsValid(&error)) Fail(root, "", error);
    return plan;
  }

 private:
  [[noreturn]] void Fail(const YAML::Node& node, const std::string& field,
                         const std::string& what) const {
    const int line = node.IsDefined() ? node.Mark().line + 1 : 0;
    throw InputError(source_, line, field, what);
  }

  static std::string Field(const std::string& section, const std::string& key) {
    return section.empty() ? key : section + "." + key;
  }

  // Every key of `map` must be in `allowed`, once. `what` names the mapping
  // in messages (default: the section).
  void CheckKeys(const YAML::Node& map, const std::string& section,
                 const std::vector<std::string>& allowed, std::string what = "") const {
    if (what.empty()) what = section;
    std::set<std::string> seen;
    for (const auto& entry : map) {
      const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : "";
      bool known = false;
      for (const std::string& name : allowed) known = known || name == key;
      if (!known) {
        Fail(entry.first, Field(section, key),
             "unknown key" + std::string(what.empty() ? "" : " in " + what) +
                 "; allowed keys: " + JoinKeys(allowed));
      }
      if (!seen.insert(key).second) {
        Fail(entry.first, Field(section, key), "key given twice; give it once");
      }
    }
  }

  YAML::Node Required(const YAML::Node& map, const std::string& key,
                      const std::string& section) const {
    const YAML::Node node = map[key];
    if (!node) {
      Fail(map, Field(section, key),
           "missing" + std::string(section.empty() ? "" : " in " + section) + "; add it");
    }
    return node;
  }

  std::string Text(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar() || node.Scalar().empty()) Fail(node, field, "must be a non-empty text");
    return node.Scalar();
  }

  double Number(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) Fail(node, field, "must be a number");
    const std::string& text = node.Scalar();
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE ||
        !std::isfinite(value)) {
      Fail(node, field, "'" + text + "' is not a finite number");
    }
    return value;
  }

  double Positive(const YAML::Node& node, const std::string& field) const {
    const double value = Number(node, field);
    if (!(value > 0.0)) Fail(node, field, "must be positive, got " + node.Scalar());
    return value;
  }

  double NonNegative(const YAML::Node& node, const std::string& field) const {
    const double value = Number(node, field);
    if (value < 0.0) Fail(node, field, "must not be negative, got " + node.Scalar());
    return value;
  }

  ParameterVector Truth(const YAML::Node& node) const {
    if (!node.IsMap()) Fail(node, "truth", "must be a mapping of the six parameters");
    const std::vector<std::string> keys = {"eta_e", "mu1", "mu2", "delta", "alpha", "omega_hz"};
    CheckKeys(node, "truth", keys);
    auto get = [&](const std::string& key) { return Required(node, key, "truth"); };
    ParameterVector p{};
    p[kEtaE] = Positive(get("eta_e"), "truth.eta_e");
    p[kMu1] = NonNegative(get("mu1"), "truth.mu1");
    p[kMu2] = NonNegative(get("mu2"), "truth.mu2");
    p[kDelta] = Number(get("delta"), "truth.delta");
    p[kAlpha] = Number(get("alpha"), "truth.alpha");
    p[kOmega] = HzToRadPerSecond(Positive(get("omega_hz"), "truth.omega_hz"));
    return p;
  }

  SweepPlan Sweep(const YAML::Node& node, const std::string& section) const {
    if (!node.IsMap()) Fail(node, section, "must be a mapping (id, kind, ...)");
    SweepPlan sweep;
    const std::string kind = Text(Required(node, "kind", section), Field(section, "kind"));
    const bool frequency = kind == "frequency";
    if (!frequency && kind != "amplitude") {
      Fail(node["kind"], Field(section, "kind"),
           "'" + kind + "' is not a sweep kind; use frequency or amplitude");
    }
    sweep.kind = frequency ? SweepKind::kFrequency : SweepKind::kAmplitude;
    const std::vector<std::string> stepped =
        frequency ? std::vector<std::string>{"a_base", "from_hz", "to_hz", "step_hz"}
                  : std::vector<std::string>{"freq_hz", "a_base_from", "a_base_to", "a_base_step"};
    std::vector<std::string> allowed = {"id", "kind", "directions", "start"};
    allowed.insert(allowed.end(), stepped.begin(), stepped.end());
    CheckKeys(node, section, allowed, section + " (" + kind + " sweep)");
    auto get = [&](const std::string& key) { return Required(node, key, section); };
    sweep.id = Text(get("id"), Field(section, "id"));
    const double held = Positive(get(stepped[0]), Field(section, stepped[0]));
    (frequency ? sweep.held_a_base : sweep.held_frequency_hz) = held;
    sweep.from = Positive(get(stepped[1]), Field(section, stepped[1]));
    sweep.to = Positive(get(stepped[2]), Field(section, stepped[2]));
    sweep.step = Positive(get(stepped[3]), Field(section, stepped[3]));
    if (node["directions"]) sweep.directions = Directions(node["directions"], section);
    if (node["start"]) {
      const std::string field = Field(section, "start");
      const std::string start = Text(node["start"], field);
      if (start == "lower") {
        sweep.start_branch = Branch::kLower;
      } else if (start == "upper") {
        sweep.start_branch = Branch::kUpper;
      } else {
        Fail(node["start"], field, "'" + start + "' is not a start branch; use lower or upper");
      }
    }
    std::string error;
    if (!sweep.IsValid(&error)) Fail(node, section, error);
    return sweep;
  }

  std::vector<SweepDirection> Directions(const YAML::Node& node, const std::string& section) const {
    const std::string field = Field(section, "directions");
    if (!node.IsSequence() || node.size() == 0) {
      Fail(node, field, "must be a list such as [up, down]");
    }
    std::vector<SweepDirection> directions;
    for (const auto& item : node) {
      SweepDirection direction;
      if (!item.IsScalar() || !SweepDirectionFromName(item.Scalar(), &direction)) {
        Fail(item, field, "each direction is up or down");
      }
      directions.push_back(direction);
    }
    return directions;
  }

  DwellNoise Noise(const YAML::Node& node) const {
    if (!node.IsMap()) Fail(node, "noise", "must be a mapping with relative_sigma and seed");
    CheckKeys(node, "noise", {"relative_sigma", "seed"});
    DwellNoise noise;
    const YAML::Node sigma = Required(node, "relative_sigma", "noise");
    noise.relative_sigma = NonNegative(sigma, "noise.relative_sigma");
    if (!(noise.relative_sigma < 1.0)) {
      Fail(sigma, "noise.relative_sigma", "must be below 1, got " + sigma.Scalar());
    }
    const YAML::Node seed = Required(node, "seed", "noise");
    const std::string text = seed.IsScalar() ? seed.Scalar() : "";
    char* end = nullptr;
    errno = 0;
    const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
        end != text.c_str() + text.size() || errno == ERANGE) {
      Fail(seed, "noise.seed", "'" + text + "' is not a non-negative integer below 2^64");
    }
    noise.seed = value;
    return noise;
  }

  std::string source_;
};

}  // namespace

DwellPlan ParseDwellPlan(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputError(source, e.mark.line + 1, "", "not valid YAML: " + e.msg);
  }
  return PlanParser(source).Parse(root);
}

DwellPlan ReadDwellPlan(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path, 0, "", "cannot open the plan file; check the path");
  std::ostringstream text;
  text << file.rdbuf();
  return ParseDwellPlan(text.str(), path);
}

}  // namespace dwellfit
