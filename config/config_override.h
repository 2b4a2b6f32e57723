// Command-line changes to a config file: `--set solver.max_iterations=50`,
// `--fix=delta,omega`, `--output_dir=/tmp/x` and the like each become a
// ConfigOverride. LoadIdentifyConfig applies them to the YAML tree after
// reading the file and before validating it, so an override passes the same
// strict checks as the file, and its errors name the flag instead of a line.
#ifndef DWELLFIT_CONFIG_CONFIG_OVERRIDE_H_
#define DWELLFIT_CONFIG_CONFIG_OVERRIDE_H_

#include <string>
#include <vector>

namespace dwellfit {

enum class OverrideAction {
  // key_path takes yaml_value; missing blocks on the way are created, and a
  // null value (`null` or `~`) removes the key.
  kReplace,
  // The entries of yaml_value (a list or one scalar) are removed from the list
  // at key_path; each must be in it (`--free=omega`).
  kRemoveFromList,
  // The entries of yaml_value are appended to the list at key_path (created
  // when missing); an entry already in it stays once (`--fix=delta`).
  kAddToList,
};

struct ConfigOverride {
  std::string key_path;    // map keys joined by '.': "solver.max_iterations"
  std::string yaml_value;  // YAML text: "50", "[delta, omega]", "{min_ratio: 3}"
  std::string origin;      // the flag that asked for it, named in errors: "--set"
  OverrideAction action = OverrideAction::kReplace;
};

// Splits a `--set` value "a.b=1,c=[x, y]" into {a.b, 1} and {c, [x, y]}.
// Commas inside [], {} or quotes do not split; space around keys and values is
// trimmed; an empty flag gives no overrides. Throws InputError naming `origin`
// for an entry without '=', an empty key or key segment ("a..b"), an empty
// value, unbalanced brackets, or a key given twice.
std::vector<ConfigOverride> ParseSetFlag(const std::string& flag_value, const std::string& origin);

// A comma-separated flag value as a YAML list override: ("fixed", "delta,omega",
// "--fix") gives {fixed, "[delta, omega]", --fix}. For --fix (kAddToList),
// --free (kRemoveFromList), --stages, --fit and --validate.
ConfigOverride ListFlagOverride(const std::string& key_path, const std::string& comma_list,
                                const std::string& origin,
                                OverrideAction action = OverrideAction::kReplace);

// "a.b.c" as {a, b, c}; an empty segment ("a..b") stays, empty.
std::vector<std::string> SplitKeyPath(const std::string& key_path);

// "--set solver.max_iterations=50", "--fix fixed+=[delta]" or "--free
// fixed-=[omega]": how the override is shown in errors and in the printed
// config.
std::string DescribeOverride(const ConfigOverride& override_value);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_CONFIG_OVERRIDE_H_
