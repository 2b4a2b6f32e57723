// Bad user input (data files, config, flags) is reported by throwing
// InputError with a message a person can act on: which file, which line,
// which field, what is wrong and what to do. CHECK is for internal invariants.
#ifndef DWELLFIT_ESTIMATOR_COMMON_INPUT_ERROR_H_
#define DWELLFIT_ESTIMATOR_COMMON_INPUT_ERROR_H_

#include <stdexcept>
#include <string>

namespace dwellfit {

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
