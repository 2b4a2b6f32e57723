#include "config/config_source.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>
#include <utility>

namespace dwellfit {
namespace {

// True when `path` is `prefix` or lies inside it ("solver" holds
// "solver.max_iterations"; "fit" holds "fit[2]").
bool PathWithin(const std::string& path, const std::string& prefix) {
  if (path.compare(0, prefix.size(), prefix) != 0) return false;
  return path.size() == prefix.size() || path[prefix.size()] == '.' || path[prefix.size()] == '[';
}

std::vector<std::string> SplitKeyPath(const std::string& key_path) {
  std::vector<std::string> segments;
  std::string::size_type begin = 0;
  while (true) {
    const std::string::size_type dot = key_path.find('.', begin);
    segments.push_back(key_path.substr(begin, dot - begin));
    if (dot == std::string::npos) return segments;
    begin = dot + 1;
  }
}

const char* NodeKindName(const YAML::Node& node) {
  if (node.IsSequence()) return "list";
  if (node.IsMap()) return "block of keys";
  return "single value";
}

int OneBasedLine(const YAML::Mark& mark) { return mark.is_null() ? 0 : mark.line + 1; }

// `list` (a list, one value, or undefined) without the entries of `to_remove`
// (a list or one value); each must be in it.
YAML::Node ListWithout(const YAML::Node& list, const YAML::Node& to_remove,
                       const ConfigOverride& override_value) {
  std::vector<YAML::Node> kept;
  if (list.IsSequence()) {
    for (const YAML::Node& entry : list) kept.push_back(entry);
  } else if (list.IsScalar()) {
    kept.push_back(list);
  }
  std::vector<YAML::Node> removed;
  if (to_remove.IsSequence()) {
    for (const YAML::Node& entry : to_remove) removed.push_back(entry);
  } else if (to_remove.IsScalar()) {
    removed.push_back(to_remove);
  }
  for (const YAML::Node& entry : removed) {
    const auto match = std::find_if(kept.begin(), kept.end(), [&](const YAML::Node& k) {
      return k.IsScalar() && entry.IsScalar() && k.Scalar() == entry.Scalar();
    });
    if (match == kept.end()) {
      YAML::Emitter shown;
      shown << (list.IsDefined() ? list : YAML::Node(YAML::NodeType::Sequence));
      throw InputError(override_value.origin, 0, override_value.key_path,
                       "cannot remove '" + (entry.IsScalar() ? entry.Scalar() : "?") +
                           "': it is not in '" + override_value.key_path + "' (" + shown.c_str() +
                           ")");
    }
    kept.erase(match);
  }
  // Kept entries are the file's nodes, so they keep their lines.
  YAML::Node new_list(YAML::NodeType::Sequence);
  for (const YAML::Node& entry : kept) new_list.push_back(entry);
  new_list.SetStyle(YAML::EmitterStyle::Flow);
  return new_list;
}

}  // namespace

ConfigSource ConfigSource::Load(const std::string& path, const std::string& kind) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    throw InputError(path, 0, "", "is a directory; give the path of the YAML " + kind);
  }
  std::ifstream stream(path);
  if (!stream) {
    throw InputError(path, 0, "", "cannot open the " + kind + "; check the path");
  }
  std::stringstream text;
  text << stream.rdbuf();
  return Parse(path, text.str());
}

ConfigSource ConfigSource::Parse(const std::string& file, const std::string& yaml_text) {
  try {
    return ConfigSource(file, YAML::Load(yaml_text));
  } catch (const YAML::ParserException& e) {
    throw InputError(file, OneBasedLine(e.mark), "", "YAML syntax error: " + e.msg);
  }
}

ConfigSource::ConfigSource(std::string file, YAML::Node root)
    : file_(std::move(file)), root_(std::move(root)) {}

void ConfigSource::Apply(const std::vector<ConfigOverride>& overrides) {
  for (const ConfigOverride& override_value : overrides) ApplyOne(override_value);
}

void ConfigSource::ApplyOne(const ConfigOverride& override_value) {
  const std::string& origin = override_value.origin;
  const std::string& key_path = override_value.key_path;
  const std::vector<std::string> segments = SplitKeyPath(key_path);
  for (const std::string& segment : segments) {
    if (segment.empty()) {
      throw InputError(origin, 0, key_path,
                       "malformed key path; write keys joined by single dots, e.g. "
                       "solver.max_iterations");
    }
  }
  YAML::Node value;
  try {
    value = YAML::Load(override_value.yaml_value);
  } catch (const YAML::ParserException& e) {
    throw InputError(origin, 0, key_path,
                     "value '" + override_value.yaml_value + "' is not valid YAML: " + e.msg);
  }
  if (!root_.IsDefined() || root_.IsNull()) root_ = YAML::Node(YAML::NodeType::Map);
  if (!root_.IsMap()) {
    throw InputError(file_, OneBasedLine(root_.Mark()), "",
                     "the config is a " + std::string(NodeKindName(root_)) +
                         ", not a block of keys, so " + DescribeOverride(override_value) +
                         " cannot be applied");
  }

  // Walk to the map that holds the last segment, creating missing blocks.
  // Node::reset rebinds `map`; assigning would overwrite the tree.
  const std::size_t index = applied_.size();
  YAML::Node map;
  map.reset(root_);
  std::string walked;
  for (std::size_t i = 0; i + 1 < segments.size(); ++i) {
    walked += (walked.empty() ? "" : ".") + segments[i];
    YAML::Node child = map[segments[i]];
    if (!child.IsDefined() || child.IsNull()) {
      map[segments[i]] = YAML::Node(YAML::NodeType::Map);
      child.reset(map[segments[i]]);
      set_paths_.push_back(SetPath{walked, index});
    } else if (!child.IsMap()) {
      throw InputError(origin, 0, key_path,
                       "'" + walked + "' holds a " + NodeKindName(child) +
                           ", not a block of keys; set '" + walked + "' itself");
    }
    map.reset(child);
  }
  const std::string& key = segments.back();

  if (override_value.action == OverrideAction::kRemoveFromList) {
    map[key] = ListWithout(map[key], value, override_value);
    // The remaining entries still come from the file: not recorded as set.
    applied_.push_back(override_value);
    return;
  }

  if (value.IsNull()) {
    // A removal that finds nothing is most likely a misspelt key: say so.
    if (!static_cast<const YAML::Node&>(map)[key].IsDefined()) {
      throw InputError(origin, 0, key_path,
                       "nothing to remove: the config does not set '" + key_path +
                           "'; check the key path (the value null removes a key)");
    }
    map.remove(key);
  } else {
    map[key] = value;
  }
  set_paths_.push_back(SetPath{key_path, index});
  applied_.push_back(override_value);
}

const ConfigOverride* ConfigSource::OverrideFor(const std::string& key_path) const {
  for (auto it = set_paths_.rbegin(); it != set_paths_.rend(); ++it) {
    if (PathWithin(key_path, it->path)) return &applied_[it->by];
  }
  return nullptr;
}

std::vector<const ConfigOverride*> ConfigSource::OverridesWithin(
    const std::string& key_path) const {
  std::vector<const ConfigOverride*> within;
  for (const ConfigOverride& applied : applied_) {
    if (PathWithin(applied.key_path, key_path)) within.push_back(&applied);
  }
  return within;
}

InputError ConfigSource::Error(const std::string& key_path, const YAML::Mark& mark,
                               const std::string& what) const {
  if (const ConfigOverride* set_by = OverrideFor(key_path)) {
    return InputError(set_by->origin, 0, key_path, what);
  }
  return InputError(file_, OneBasedLine(mark), key_path, what);
}

std::string ConfigSource::Where(const std::string& key_path, const YAML::Mark& mark) const {
  if (const ConfigOverride* set_by = OverrideFor(key_path)) return set_by->origin;
  if (mark.is_null()) return file_;
  return "line " + std::to_string(mark.line + 1);
}

}  // namespace dwellfit
