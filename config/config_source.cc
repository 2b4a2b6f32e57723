#include "dwellfit/config/config_source.h"

#include <algorithm>
#include <optional>
#include <sstream>
#include <utility>

#include "dwellfit/config/strict_yaml.h"
#include "dwellfit/estimator/common/text_file.h"
#include "yaml-cpp/depthguard.h"
#include "yaml-cpp/eventhandler.h"
#include "yaml-cpp/parser.h"

namespace dwellfit {
namespace {

// Documents a config file may hold before the reader gives up (see
// DocumentWalker).
constexpr int kMaxDocuments = 1000;

// Walks the documents of a YAML text without building them and keeps where a
// second document with content starts. yaml-cpp 0.7's LoadAll never returns
// on some malformed text (a stray ',' or '}' at the top level: its parser
// yields empty documents without advancing), so the caller bounds the walk.
class DocumentWalker : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override { ++documents_; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { Content(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Content(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Content(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Content(mark);
  }
  void OnMapEnd() override {}

  int documents() const { return documents_; }
  const std::optional<YAML::Mark>& second_document() const { return second_document_; }

 private:
  void Content(const YAML::Mark& mark) {
    if (documents_ >= 2 && !second_document_) second_document_ = mark;
  }

  int documents_ = 0;
  std::optional<YAML::Mark> second_document_;
};

// True when `path` is `prefix` or lies inside it ("solver" holds
// "solver.max_iterations"; "fit" holds "fit[2]").
bool PathWithin(const std::string& path, const std::string& prefix) {
  if (path.compare(0, prefix.size(), prefix) != 0) return false;
  return path.size() == prefix.size() || path[prefix.size()] == '.' || path[prefix.size()] == '[';
}

int OneBasedLine(const YAML::Mark& mark) { return mark.is_null() ? 0 : mark.line + 1; }

// The entries of the list at an override's key: a list's entries, one value
// as one entry, none for an absent key. Throws for a block of keys.
std::vector<YAML::Node> ListEntries(const YAML::Node& list, const ConfigOverride& override_value) {
  std::vector<YAML::Node> entries;
  if (list.IsMap()) {
    throw InputError(override_value.origin, 0, override_value.key_path,
                     "'" + override_value.key_path +
                         "' holds a block of keys, not a list, so entries cannot be added to "
                         "or removed from it");
  }
  if (list.IsSequence()) {
    for (const YAML::Node& entry : list) entries.push_back(entry);
  } else if (list.IsScalar()) {
    entries.push_back(list);
  }
  return entries;
}

bool SameScalar(const YAML::Node& a, const YAML::Node& b) {
  return a.IsScalar() && b.IsScalar() && a.Scalar() == b.Scalar();
}

// `entries` as a new flow-style list; the entries are the same nodes, so
// those from the file keep their lines.
YAML::Node FlowList(const std::vector<YAML::Node>& entries) {
  YAML::Node list(YAML::NodeType::Sequence);
  for (const YAML::Node& entry : entries) list.push_back(entry);
  list.SetStyle(YAML::EmitterStyle::Flow);
  return list;
}

// `list` without the entries of `to_remove` (a list or one value); each must
// be in it.
YAML::Node ListWithout(const YAML::Node& list, const YAML::Node& to_remove,
                       const ConfigOverride& override_value) {
  std::vector<YAML::Node> kept = ListEntries(list, override_value);
  for (const YAML::Node& entry : ListEntries(to_remove, override_value)) {
    const auto match = std::find_if(kept.begin(), kept.end(),
                                    [&](const YAML::Node& k) { return SameScalar(k, entry); });
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
  return FlowList(kept);
}

// `list` with the entries of `to_add` that it lacks appended; those are
// also appended to `*added`.
YAML::Node ListWith(const YAML::Node& list, const YAML::Node& to_add,
                    const ConfigOverride& override_value, std::vector<YAML::Node>* added) {
  std::vector<YAML::Node> entries = ListEntries(list, override_value);
  for (const YAML::Node& entry : ListEntries(to_add, override_value)) {
    if (std::none_of(entries.begin(), entries.end(),
                     [&](const YAML::Node& e) { return SameScalar(e, entry); })) {
      entries.push_back(entry);
      added->push_back(entry);
    }
  }
  return FlowList(entries);
}

// `initial_guess: auto`, the block written as the single word `auto`: every
// key of it auto, the same as a block that gives none (the one block of the
// schema that may be written so).
bool StandsForEmptyBlock(const std::string& path, const YAML::Node& node) {
  return path == "initial_guess" && node.IsScalar() && node.Scalar() == "auto";
}

// The value of `key` in `map`; a null node when the key is absent.
YAML::Node Get(const YAML::Node& map, const std::string& key) {
  const YAML::Node value = map[key];  // const access adds no key
  return value.IsDefined() ? value : YAML::Node();
}

// A copy of the block `block`: a map of its own whose entries are the same
// nodes (so they keep their lines).
YAML::Node ShallowCopy(const YAML::Node& block) {
  YAML::Node copy(YAML::NodeType::Map);
  for (auto it = block.begin(); it != block.end(); ++it) copy[it->first] = it->second;
  return copy;
}

// Sets `key` of `*map` to `value` and returns the value's node there. A
// yaml-cpp assignment would write into the node the key held, which a YAML
// alias shares with another key; so the entry is removed and added again,
// with its key node (and so the key's line).
YAML::Node Rebind(YAML::Node* map, const std::string& key, const YAML::Node& value) {
  YAML::Node key_node(key);
  for (auto it = map->begin(); it != map->end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) key_node.reset(it->first);
  }
  map->remove(key);
  (*map)[key_node] = value;
  return (*map)[key_node];
}

// The names a list override gives ("[delta, omega]"); none when its value is
// not a list of names.
std::vector<std::string> ListedNames(const ConfigOverride& override_value) {
  std::vector<std::string> names;
  try {
    const YAML::Node list = YAML::Load(override_value.yaml_value);
    if (list.IsSequence()) {
      for (const YAML::Node& entry : list) {
        if (entry.IsScalar()) names.push_back(entry.Scalar());
      }
    }
  } catch (const YAML::Exception&) {
    // Applying it reports the syntax error.
  }
  return names;
}

// Throws when two overrides change the same key or one a key inside the
// other's: only --fix and --free may both change one list, with different
// names.
void CheckNoConflicts(const std::vector<ConfigOverride>& overrides) {
  for (std::size_t j = 0; j < overrides.size(); ++j) {
    const ConfigOverride& later = overrides[j];
    for (std::size_t i = 0; i < j; ++i) {
      const ConfigOverride& earlier = overrides[i];
      if (!PathWithin(later.key_path, earlier.key_path) &&
          !PathWithin(earlier.key_path, later.key_path)) {
        continue;
      }
      const bool edits = earlier.action != OverrideAction::kReplace &&
                         later.action != OverrideAction::kReplace &&
                         earlier.key_path == later.key_path;
      if (!edits) {
        throw InputError(
            later.origin, 0, later.key_path,
            "conflicts with " + DescribeOverride(earlier) + ": both change it; give each key once");
      }
      if (earlier.action == later.action) continue;
      for (const std::string& name : ListedNames(later)) {
        const std::vector<std::string> names = ListedNames(earlier);
        if (std::find(names.begin(), names.end(), name) != names.end()) {
          throw InputError(later.origin, 0, later.key_path,
                           "'" + name + "' is given to both " + earlier.origin + " and " +
                               later.origin + "; give it to one of them");
        }
      }
    }
  }
}

}  // namespace

ConfigSource ConfigSource::Load(const std::string& path, const std::string& kind) {
  return Parse(path, ReadTextFile(path, "give the path of the YAML " + kind));
}

ConfigSource ConfigSource::Parse(const std::string& file, const std::string& yaml_text) {
  YAML::Node root;
  try {
    std::stringstream stream(yaml_text);
    YAML::Parser parser(stream);
    DocumentWalker walker;
    while (parser.HandleNextDocument(walker)) {
      // Later documents are not read: one with content is an error, not ignored.
      if (walker.second_document()) {
        throw InputError(file, OneBasedLine(*walker.second_document()), "",
                         "a second YAML document starts here (after a '---' line), and only the "
                         "first would be read; the file holds one document: move these keys into "
                         "the first one, or remove the '---' line");
      }
      if (walker.documents() > kMaxDocuments) {
        throw InputError(file, 0, "",
                         "YAML syntax error: the reader does not get past a stray ',', '}' or "
                         "']' outside brackets; check the punctuation of the file");
      }
    }
    root = YAML::Load(yaml_text);
  } catch (const YAML::DeepRecursion& e) {
    throw InputError(file, OneBasedLine(e.mark), "",
                     "the YAML is nested too deeply (the reader stops at " +
                         std::to_string(e.depth()) +
                         " levels); a config's blocks and lists are a few levels deep: look for "
                         "runaway brackets or indentation here");
  } catch (const YAML::ParserException& e) {
    throw InputError(file, OneBasedLine(e.mark), "", "YAML syntax error: " + e.msg);
  }
  return ConfigSource(file, root);
}

ConfigSource::ConfigSource(std::string file, YAML::Node root)
    : file_(std::move(file)), root_(std::move(root)) {}

void ConfigSource::Apply(const std::vector<ConfigOverride>& overrides) {
  CheckNoConflicts(overrides);
  for (const ConfigOverride& override_value : overrides) ApplyOne(override_value);
}

YAML::Node ConfigSource::ParseValue(const ConfigOverride& override_value) const {
  const std::string& origin = override_value.origin;
  const std::string& key_path = override_value.key_path;
  if (override_value.yaml_value.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InputError(origin, 0, key_path,
                     "the flag's value is empty; give a value for '" + key_path + "'");
  }
  YAML::Node value;
  try {
    value = YAML::Load(override_value.yaml_value);
  } catch (const YAML::DeepRecursion&) {
    throw InputError(origin, 0, key_path, "the value is nested too deeply to be a config value");
  } catch (const YAML::ParserException& e) {
    throw InputError(
        origin, 0, key_path,
        "value '" + EscapeForMessage(override_value.yaml_value) + "' is not valid YAML: " + e.msg);
  }
  const bool edit = override_value.action != OverrideAction::kReplace;
  if (edit && (value.IsNull() || (value.IsSequence() && value.size() == 0))) {
    throw InputError(
        origin, 0, key_path,
        "the flag's value is empty; give the names to " +
            std::string(override_value.action == OverrideAction::kAddToList ? "add to '"
                                                                            : "remove from '") +
            key_path + "'");
  }
  return value;
}

YAML::Node ConfigSource::WalkToParent(const ConfigOverride& override_value,
                                      const std::vector<std::string>& segments) {
  const std::size_t index = applied_.size();
  YAML::Node map;
  map.reset(root_);  // Node::reset rebinds `map`; assigning would overwrite the tree
  std::string walked;
  for (std::size_t i = 0; i + 1 < segments.size(); ++i) {
    walked += (walked.empty() ? "" : ".") + segments[i];
    const YAML::Node child = Get(map, segments[i]);
    YAML::Node next;
    if (child.IsNull()) {
      next.reset(Rebind(&map, segments[i], YAML::Node(YAML::NodeType::Map)));
      set_paths_.push_back(SetPath{walked, index});
    } else if (StandsForEmptyBlock(walked, child)) {
      // `initial_guess: auto` is the block with every key auto: setting one
      // key opens it into a block holding that key (the others stay auto).
      next.reset(Rebind(&map, segments[i], YAML::Node(YAML::NodeType::Map)));
    } else if (!child.IsMap()) {
      throw InputError(override_value.origin, 0, override_value.key_path,
                       "'" + walked + "' holds " + DescribeKind(child) +
                           ", not a block of keys; set '" + walked + "' itself");
    } else {
      next.reset(Rebind(&map, segments[i], ShallowCopy(child)));
    }
    map.reset(next);
  }
  return map;
}

void ConfigSource::ApplyOne(const ConfigOverride& override_value) {
  const std::string& key_path = override_value.key_path;
  const std::vector<std::string> segments = SplitKeyPath(key_path);
  for (const std::string& segment : segments) {
    if (segment.empty()) {
      throw InputError(override_value.origin, 0, key_path,
                       "malformed key path; write keys joined by single dots, e.g. "
                       "solver.max_iterations");
    }
  }
  const YAML::Node value = ParseValue(override_value);
  if (!root_.IsDefined() || root_.IsNull()) root_ = YAML::Node(YAML::NodeType::Map);
  if (!root_.IsMap()) {
    throw InputError(file_, OneBasedLine(root_.Mark()), "",
                     "the config is " + std::string(DescribeKind(root_)) +
                         ", not a block of keys, so " + DescribeOverride(override_value) +
                         " cannot be applied");
  }
  const std::size_t index = applied_.size();
  YAML::Node map = WalkToParent(override_value, segments);
  const std::string& key = segments.back();
  const YAML::Node current = Get(map, key);
  if (override_value.action == OverrideAction::kRemoveFromList) {
    // The remaining entries still come from the file: not recorded as set.
    Rebind(&map, key, ListWithout(current, value, override_value));
  } else if (override_value.action == OverrideAction::kAddToList) {
    std::vector<YAML::Node> added;
    Rebind(&map, key, ListWith(current, value, override_value, &added));
    for (const YAML::Node& entry : added) added_.emplace_back(entry, index);
  } else {
    if (value.IsNull()) {
      // A removal that finds nothing is most likely a misspelt key: say so.
      if (!static_cast<const YAML::Node&>(map)[key].IsDefined()) {
        throw InputError(override_value.origin, 0, key_path,
                         "nothing to remove: the config does not set '" + key_path +
                             "'; check the key path (the value null removes a key)");
      }
      map.remove(key);
    } else {
      Rebind(&map, key, value);
    }
    set_paths_.push_back(SetPath{key_path, index});
  }
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

const ConfigOverride* ConfigSource::AddedBy(const YAML::Node& entry) const {
  for (const auto& [node, by] : added_) {
    if (node.is(entry)) return &applied_[by];
  }
  return nullptr;
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
