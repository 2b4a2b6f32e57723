// printf-style formatting into a std::string of any length: the one
// formatting helper of the library (tables, messages, numbers in reports).
#ifndef DWELLFIT_ESTIMATOR_COMMON_STRING_PRINTF_H_
#define DWELLFIT_ESTIMATOR_COMMON_STRING_PRINTF_H_

#include <string>

namespace dwellfit {

// StringPrintf("%.6g Hz", 42.2) == "42.2 Hz". The format is checked at compile
// time against the arguments.
std::string StringPrintf(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_STRING_PRINTF_H_
