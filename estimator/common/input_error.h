// Bad user input (data files, config, flags) is reported by throwing
// InputError with a message a person can act on: which file, which line,
// which field, what is wrong and what to do. CHECK is for internal invariants.
#ifndef DWELLFIT_ESTIMATOR_COMMON_INPUT_ERROR_H_
#define DWELLFIT_ESTIMATOR_COMMON_INPUT_ERROR_H_

#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>

namespace dwellfit {

// `text` as it may be echoed in a message: printable ASCII and well-formed
// UTF-8 sequences are kept, tab, CR and LF become \t, \r and \n, and every
// other byte \xNN; after `max_chars` characters of the text the rest is cut
// ("... (N bytes in all)"), so that a binary or huge field cannot garble or
// flood the message.
inline std::string EscapeForMessage(std::string_view text, std::size_t max_chars = 40) {
  std::string escaped;
  std::size_t shown = 0;
  std::size_t i = 0;
  for (; i < text.size() && shown < max_chars; ++shown) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    // The length of a UTF-8 sequence led by `c` (0: not a lead byte).
    const std::size_t length = c >= 0xF5 ? 0 : c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
    bool sequence = length > 0 && i + length <= text.size();
    for (std::size_t k = 1; sequence && k < length; ++k) {
      sequence = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    }
    if (sequence) {
      escaped.append(text.substr(i, length));
      i += length;
      continue;
    }
    ++i;
    if (c == '\t') {
      escaped += "\\t";
    } else if (c == '\r') {
      escaped += "\\r";
    } else if (c == '\n') {
      escaped += "\\n";
    } else if (c >= 0x20 && c < 0x7F) {
      escaped += static_cast<char>(c);
    } else {
      char hex[5];
      std::snprintf(hex, sizeof(hex), "\\x%02X", c);
      escaped += hex;
    }
  }
  if (i < text.size()) escaped += "... (" + std::to_string(text.size()) + " bytes in all)";
  return escaped;
}

class InputError : public std::runtime_error {
 public:
  // Formats "<file>:<line>: field '<field>': <what>". `line` <= 0 and an
  // empty `field` are left out.
  InputError(const std::string& file, int line, const std::string& field, const std::string& what)
      : std::runtime_error(Format(file, line, field, what)),
        file_(file),
        line_(line),
        field_(field) {}
  explicit InputError(const std::string& what) : std::runtime_error(what), line_(0) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& field() const { return field_; }

 private:
  static std::string Format(const std::string& file, int line, const std::string& field,
                            const std::string& what) {
    std::string message = file;
    if (line > 0) message += ":" + std::to_string(line);
    message += ": ";
    if (!field.empty()) message += "field '" + field + "': ";
    return message + what;
  }

  std::string file_;
  int line_;
  std::string field_;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_INPUT_ERROR_H_
