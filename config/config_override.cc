#include "dwellfit/config/config_override.h"

#include <sstream>

#include "dwellfit/estimator/common/input_error.h"

namespace dwellfit {
namespace {

std::string Trim(const std::string& text) {
  const char* kSpace = " \t\r\n";
  const std::string::size_type begin = text.find_first_not_of(kSpace);
  if (begin == std::string::npos) return "";
  const std::string::size_type end = text.find_last_not_of(kSpace);
  return text.substr(begin, end - begin + 1);
}

// Splits at top-level commas: not inside [], {} or quotes. Throws on
// unbalanced brackets or an unterminated quote.
std::vector<std::string> SplitTopLevel(const std::string& text, const std::string& origin) {
  std::vector<std::string> parts;
  std::string current;
  std::string open_brackets;  // stack of the closers expected
  char quote = 0;
  for (char c : text) {
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '[' || c == '{') {
      open_brackets.push_back(c == '[' ? ']' : '}');
    } else if (c == ']' || c == '}') {
      if (open_brackets.empty() || open_brackets.back() != c) {
        throw InputError(origin, 0, "",
                         "unbalanced '" + std::string(1, c) + "' in '" + text +
                             "'; write lists as key=[a, b] and blocks as key={k: v}");
      }
      open_brackets.pop_back();
    } else if (c == ',' && open_brackets.empty()) {
      parts.push_back(current);
      current.clear();
      continue;
    }
    current.push_back(c);
  }
  if (quote != 0) {
    throw InputError(origin, 0, "",
                     "unterminated quote " + std::string(1, quote) + " in '" + text + "'");
  }
  if (!open_brackets.empty()) {
    throw InputError(origin, 0, "",
                     "missing '" + std::string(1, open_brackets.back()) + "' in '" + text +
                         "'; write lists as key=[a, b] and blocks as key={k: v}");
  }
  parts.push_back(current);
  return parts;
}

void CheckKeyPath(const std::string& key_path, const std::string& entry,
                  const std::string& origin) {
  if (key_path.empty()) {
    throw InputError(origin, 0, "",
                     "entry '" + entry + "' has no key before '='; write " +
                         "key.path=value, e.g. solver.max_iterations=50");
  }
  for (const std::string& segment : SplitKeyPath(key_path)) {
    if (segment.empty() || segment.find_first_of(" \t") != std::string::npos) {
      throw InputError(origin, 0, "",
                       "key path '" + key_path + "' in '" + entry +
                           "' is malformed; write keys joined by single dots, e.g. " +
                           "solver.max_iterations=50");
    }
  }
}

}  // namespace

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

std::vector<ConfigOverride> ParseSetFlag(const std::string& flag_value, const std::string& origin) {
  std::vector<ConfigOverride> overrides;
  if (Trim(flag_value).empty()) return overrides;
  // No command line holds one; the printed config would end there.
  if (flag_value.find('\0') != std::string::npos) {
    throw InputError(origin, 0, "", "the value holds a NUL character; remove it");
  }
  for (const std::string& part : SplitTopLevel(flag_value, origin)) {
    const std::string entry = Trim(part);
    if (entry.empty()) {
      throw InputError(origin, 0, "",
                       "empty entry in '" + flag_value +
                           "'; separate entries by single commas, e.g. " +
                           "solver.max_iterations=50,residual.error=relative");
    }
    const std::string::size_type equals = entry.find('=');
    if (equals == std::string::npos) {
      throw InputError(origin, 0, "",
                       "entry '" + entry + "' has no '='; write key.path=value, " +
                           "e.g. solver.max_iterations=50");
    }
    ConfigOverride override_value;
    override_value.key_path = Trim(entry.substr(0, equals));
    override_value.yaml_value = Trim(entry.substr(equals + 1));
    override_value.origin = origin;
    CheckKeyPath(override_value.key_path, entry, origin);
    if (override_value.yaml_value.empty()) {
      throw InputError(origin, 0, override_value.key_path,
                       "entry '" + entry + "' has no value after '='; to remove an optional " +
                           "key write " + override_value.key_path + "=null");
    }
    for (const ConfigOverride& earlier : overrides) {
      if (earlier.key_path == override_value.key_path) {
        throw InputError(origin, 0, override_value.key_path,
                         "'" + override_value.key_path + "' is set twice (" + earlier.key_path +
                             "=" + earlier.yaml_value + " and " + entry + "); give each key once");
      }
    }
    overrides.push_back(override_value);
  }
  return overrides;
}

ConfigOverride ListFlagOverride(const std::string& key_path, const std::string& comma_list,
                                const std::string& origin, OverrideAction action) {
  std::string entries;
  std::istringstream items(comma_list);
  for (std::string item; std::getline(items, item, ',');) {
    item = Trim(item);
    if (!item.empty()) entries += (entries.empty() ? "" : ", ") + item;
  }
  return ConfigOverride{key_path, "[" + entries + "]", origin, action};
}

std::string DescribeOverride(const ConfigOverride& override_value) {
  const char* op = override_value.action == OverrideAction::kReplace     ? "="
                   : override_value.action == OverrideAction::kAddToList ? "+="
                                                                         : "-=";
  return override_value.origin + " " + override_value.key_path + op + override_value.yaml_value;
}

}  // namespace dwellfit
