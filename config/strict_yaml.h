// Strict reading of a config's YAML tree: every key of a block must be one of
// the keys the block allows and may appear once; every value must have the
// type asked for. Every error goes through ConfigSource::Error, so it names
// the file, the 1-based line and the key path (or the overriding flag).
#ifndef DWELLFIT_CONFIG_STRICT_YAML_H_
#define DWELLFIT_CONFIG_STRICT_YAML_H_

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dwellfit/config/config_source.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {

// One value of the config and where it is.
struct ConfigValue {
  YAML::Node node;
  std::string path;  // "solver.max_iterations"; "" for the whole document
  YAML::Mark mark;   // the key's position (the entry's for list entries)
};

// The whole document of `source`, as the value to read the top-level block from.
ConfigValue DocumentValue(const ConfigSource& source);

// A block of keys read strictly. The constructor throws InputError when the
// value is not a block, a key repeats, or a key is not in `allowed_keys` (the
// message lists the allowed keys and suggests the nearest one). A block with
// no value (`solver:` alone) counts as empty.
class StrictMap {
 public:
  StrictMap(const ConfigValue& block, const ConfigSource& source,
            std::vector<std::string> allowed_keys);

  std::optional<ConfigValue> Optional(const std::string& key) const;
  // Throws InputError "missing required key" ending with `hint` (what to add).
  ConfigValue Required(const std::string& key, const std::string& hint) const;
  // Reads `key`, when present, into `value` (ReadFiniteDouble, ReadInt,
  // ReadBool); leaves `value` as it is when absent.
  void Read(const std::string& key, double* value) const;
  void Read(const std::string& key, int* value) const;
  void Read(const std::string& key, bool* value) const;

  const ConfigValue& block() const { return block_; }

 private:
  std::string ChildPath(const std::string& key) const;
  std::string Where() const;  // "in 'solver'" or "at the top level"

  ConfigValue block_;
  const ConfigSource& source_;
  std::vector<std::string> allowed_keys_;
  std::map<std::string, ConfigValue> entries_;
};

// Typed values; each throws InputError on a value of the wrong type.
double ReadFiniteDouble(const ConfigValue& value, const ConfigSource& source);
// A finite number > 0, and one >= 0.
double ReadPositive(const ConfigValue& value, const ConfigSource& source);
double ReadNonNegative(const ConfigValue& value, const ConfigSource& source);
int ReadInt(const ConfigValue& value, const ConfigSource& source);
std::uint64_t ReadUint64(const ConfigValue& value, const ConfigSource& source);
bool ReadBool(const ConfigValue& value, const ConfigSource& source);
std::string ReadNonEmptyString(const ConfigValue& value, const ConfigSource& source);
// A name that must be one of `allowed`; else the error "unknown <what> 'x'"
// with a did-you-mean and the allowed names.
std::string ReadOneOf(const ConfigValue& value, const ConfigSource& source, const std::string& what,
                      const std::vector<std::string>& allowed);
// The entries of a list; a single value counts as a one-entry list. Entries
// keep the list's path and carry their own position.
std::vector<ConfigValue> ReadList(const ConfigValue& value, const ConfigSource& source);

// "a list", "a block of keys", "nothing" or "a single value".
const char* DescribeKind(const YAML::Node& node);
// "a, b, c".
std::string JoinNames(const std::vector<std::string>& names);
// " (did you mean 'max_iterations'?)" when `word` is a likely typo of one of
// `candidates`, else "".
std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_STRICT_YAML_H_
