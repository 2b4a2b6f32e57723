#include "dwellfit/config/strict_yaml.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <utility>

namespace dwellfit {
namespace {

// The scalar text of `value`, or an error saying `expected` was wanted.
const std::string& ScalarText(const ConfigValue& value, const ConfigSource& source,
                              const std::string& expected) {
  if (!value.node.IsScalar()) {
    throw source.Error(value.path, value.mark,
                       "expected " + expected + ", got " + DescribeKind(value.node));
  }
  return value.node.Scalar();
}

// Edits (insert, delete, substitute, swap adjacent) turning `a` into `b`.
std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min(
          {d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

// `value` read as a Number by std::from_chars (a leading '+' allowed). The
// error names `kind` for a value that is not a single one, else `expected`.
template <typename Number>
Number ReadNumber(const ConfigValue& value, const ConfigSource& source, const std::string& kind,
                  const std::string& expected) {
  const std::string& text = ScalarText(value, source, kind);
  const char* begin = text.data() + (text.size() > 0 && text[0] == '+');  // from_chars rejects '+'
  const char* end = text.data() + text.size();
  Number number = 0;
  const auto [stop, error] = std::from_chars(begin, end, number);
  if (error != std::errc() || stop != end) {
    throw source.Error(value.path, value.mark,
                       "expected " + expected + ", got '" + EscapeForMessage(text) + "'");
  }
  return number;
}

}  // namespace

const char* DescribeKind(const YAML::Node& node) {
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a block of keys";
  if (node.IsNull()) return "nothing";
  return "a single value";
}

ConfigValue DocumentValue(const ConfigSource& source) {
  // No position: "missing key" errors at the top level have no line to show.
  return ConfigValue{source.root(), "", YAML::Mark::null_mark()};
}

StrictMap::StrictMap(const ConfigValue& block, const ConfigSource& source,
                     std::vector<std::string> allowed_keys)
    : block_(block), source_(source), allowed_keys_(std::move(allowed_keys)) {
  const std::string where = Where();
  if (!block_.node.IsDefined() || block_.node.IsNull()) return;
  if (!block_.node.IsMap()) {
    throw source_.Error(block_.path, block_.mark,
                        "expected a block of keys (" + JoinNames(allowed_keys_) + "), got " +
                            DescribeKind(block_.node));
  }
  for (auto it = block_.node.begin(); it != block_.node.end(); ++it) {
    // A copy: yaml-cpp's iterator yields its pair by value, so a reference
    // to `it->first` would outlive the temporary it points into.
    const YAML::Node key_node = it->first;
    if (!key_node.IsScalar()) {
      throw source_.Error(
          block_.path, key_node.Mark(),
          "a key " + where + " is not a plain name; allowed: " + JoinNames(allowed_keys_));
    }
    const std::string& key = key_node.Scalar();
    const std::string path = ChildPath(key);
    if (std::find(allowed_keys_.begin(), allowed_keys_.end(), key) == allowed_keys_.end()) {
      throw source_.Error(ChildPath(EscapeForMessage(key)), key_node.Mark(),
                          "unknown key '" + EscapeForMessage(key) + "' " + where +
                              DidYouMean(key, allowed_keys_) +
                              "; allowed: " + JoinNames(allowed_keys_));
    }
    const auto previous = entries_.find(key);
    if (previous != entries_.end()) {
      throw source_.Error(path, key_node.Mark(),
                          "key '" + key + "' appears twice " + where + " (first at " +
                              source_.Where(path, previous->second.mark) + "); keep one");
    }
    entries_.emplace(key, ConfigValue{it->second, path, key_node.Mark()});
  }
}

std::string StrictMap::ChildPath(const std::string& key) const {
  return block_.path.empty() ? key : block_.path + "." + key;
}

std::string StrictMap::Where() const {
  return block_.path.empty() ? "at the top level" : "in '" + block_.path + "'";
}

std::optional<ConfigValue> StrictMap::Optional(const std::string& key) const {
  const auto entry = entries_.find(key);
  if (entry == entries_.end()) return std::nullopt;
  return entry->second;
}

void StrictMap::Read(const std::string& key, double* value) const {
  if (const auto v = Optional(key)) *value = ReadFiniteDouble(*v, source_);
}

void StrictMap::Read(const std::string& key, int* value) const {
  if (const auto v = Optional(key)) *value = ReadInt(*v, source_);
}

void StrictMap::Read(const std::string& key, bool* value) const {
  if (const auto v = Optional(key)) *value = ReadBool(*v, source_);
}

ConfigValue StrictMap::Required(const std::string& key, const std::string& hint) const {
  const auto entry = entries_.find(key);
  if (entry != entries_.end()) return entry->second;
  // Located at the block's key: "missing" has no line of its own.
  throw source_.Error(ChildPath(key), block_.mark,
                      "missing required key '" + key + "' " + Where() + "; " + hint);
}

double ReadFiniteDouble(const ConfigValue& value, const ConfigSource& source) {
  const double number =
      ReadNumber<double>(value, source, "a number", "a number (e.g. 130, 0.26 or 1.3e4)");
  if (!std::isfinite(number)) {
    throw source.Error(
        value.path, value.mark,
        "expected a finite number, got '" + EscapeForMessage(value.node.Scalar()) + "'");
  }
  return number;
}

double ReadPositive(const ConfigValue& value, const ConfigSource& source) {
  const double number = ReadFiniteDouble(value, source);
  if (!(number > 0.0)) {
    throw source.Error(value.path, value.mark, "must be positive, got " + value.node.Scalar());
  }
  return number;
}

double ReadNonNegative(const ConfigValue& value, const ConfigSource& source) {
  const double number = ReadFiniteDouble(value, source);
  if (number < 0.0) {
    throw source.Error(value.path, value.mark, "must not be negative, got " + value.node.Scalar());
  }
  return number;
}

int ReadInt(const ConfigValue& value, const ConfigSource& source) {
  return ReadNumber<int>(value, source, "an integer", "a whole number (e.g. 200)");
}

std::uint64_t ReadUint64(const ConfigValue& value, const ConfigSource& source) {
  return ReadNumber<std::uint64_t>(value, source, "an integer",
                                   "a whole number from 0 to 2^64 - 1");
}

bool ReadBool(const ConfigValue& value, const ConfigSource& source) {
  const std::string& text = ScalarText(value, source, "true or false");
  if (text == "true" || text == "True" || text == "TRUE") return true;
  if (text == "false" || text == "False" || text == "FALSE") return false;
  throw source.Error(value.path, value.mark,
                     "expected true or false, got '" + EscapeForMessage(text) + "'");
}

std::string ReadNonEmptyString(const ConfigValue& value, const ConfigSource& source) {
  const std::string& text = ScalarText(value, source, "a single value");
  if (text.empty()) throw source.Error(value.path, value.mark, "must not be empty");
  // ("\0" in a double-quoted YAML string.) A path or name would end there.
  if (text.find('\0') != std::string::npos) {
    throw source.Error(value.path, value.mark, "holds a NUL character; remove it");
  }
  return text;
}

std::string ReadOneOf(const ConfigValue& value, const ConfigSource& source, const std::string& what,
                      const std::vector<std::string>& allowed) {
  const std::string name = ReadNonEmptyString(value, source);
  if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
    throw source.Error(value.path, value.mark,
                       "unknown " + what + " '" + EscapeForMessage(name) + "'" +
                           DidYouMean(name, allowed) + "; allowed: " + JoinNames(allowed));
  }
  return name;
}

std::vector<ConfigValue> ReadList(const ConfigValue& value, const ConfigSource& source) {
  if (value.node.IsScalar()) return {value};
  if (!value.node.IsSequence()) {
    throw source.Error(
        value.path, value.mark,
        std::string("expected a list such as [a, b], got ") + DescribeKind(value.node));
  }
  std::vector<ConfigValue> entries;
  for (const YAML::Node& entry : value.node) {
    const YAML::Mark mark = entry.Mark().is_null() ? value.mark : entry.Mark();
    entries.push_back(ConfigValue{entry, value.path, mark});
  }
  return entries;
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string* best = nullptr;
  std::size_t best_distance = 0;
  for (const std::string& candidate : candidates) {
    const std::size_t distance = EditDistance(word, candidate);
    if (best == nullptr || distance < best_distance) {
      best = &candidate;
      best_distance = distance;
    }
  }
  if (best == nullptr) return "";
  const std::size_t limit = std::max<std::size_t>(1, std::min(word.size(), best->size()) / 3);
  if (best_distance > limit) return "";
  return " (did you mean '" + *best + "'?)";
}

}  // namespace dwellfit
