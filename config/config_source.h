// A config's YAML tree and where each part of it came from: a line of the
// config file, or a command-line override. Every config error is built here,
// so it names the file and 1-based line, or the flag that set the value.
#ifndef DWELLFIT_CONFIG_CONFIG_SOURCE_H_
#define DWELLFIT_CONFIG_CONFIG_SOURCE_H_

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "dwellfit/estimator/common/input_error.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {

class ConfigSource {
 public:
  // Reads and parses the file at `path` (`kind` names it in messages), or
  // parses `yaml_text` (`file` names it). Throws InputError when the file
  // cannot be read or is not valid YAML (with the line of the syntax error).
  static ConfigSource Load(const std::string& path, const std::string& kind = "config file");
  static ConfigSource Parse(const std::string& file, const std::string& yaml_text);

  // `file` is the name used in errors.
  ConfigSource(std::string file, YAML::Node root);

  // Applies `overrides` in order to the tree (see ConfigOverride). Throws
  // InputError naming the override's origin when its value is empty or not
  // YAML, its key path runs through a value that is not a block of keys
  // (`initial_guess: auto` counts as the empty block it stands for), or
  // it changes a key another override changes too (only --fix and --free
  // may both touch one list, with different names). A block on the way to
  // the key is copied before it is written, so a YAML alias of it elsewhere
  // in the file keeps its values.
  void Apply(const std::vector<ConfigOverride>& overrides);

  const YAML::Node& root() const { return root_; }

  // The last override that set `key_path`, a block containing it, or created
  // such a block; nullptr when the value comes from the file.
  const ConfigOverride* OverrideFor(const std::string& key_path) const;
  // Overrides applied to `key_path` or to a key inside it, in order.
  std::vector<const ConfigOverride*> OverridesWithin(const std::string& key_path) const;
  // The override that added `entry` to a list (kAddToList), or nullptr when
  // the entry comes from the file.
  const ConfigOverride* AddedBy(const YAML::Node& entry) const;

  // An error about the value at `key_path` (the InputError field), located at
  // `mark` in the file, or at the override's flag when an override set it.
  InputError Error(const std::string& key_path, const YAML::Mark& mark,
                   const std::string& what) const;
  // "line 12" or "--set": where the value at `key_path` was written, for
  // messages that refer to a second place.
  std::string Where(const std::string& key_path, const YAML::Mark& mark) const;

 private:
  void ApplyOne(const ConfigOverride& override_value);
  // The value `override_value` sets: its YAML text parsed, and checked.
  YAML::Node ParseValue(const ConfigOverride& override_value) const;
  // The block that holds the last key of `segments`, created or copied on the
  // way (see Apply).
  YAML::Node WalkToParent(const ConfigOverride& override_value,
                          const std::vector<std::string>& segments);

  std::string file_;
  YAML::Node root_;
  std::vector<ConfigOverride> applied_;
  // A path whose value an override set (its key path, and every block it
  // created on the way), and the index of that override in applied_.
  struct SetPath {
    std::string path;
    std::size_t by;
  };
  std::vector<SetPath> set_paths_;
  // Entries added to a list by a kAddToList override, with its index in applied_.
  std::vector<std::pair<YAML::Node, std::size_t>> added_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_CONFIG_SOURCE_H_
