// The dwellfit release this library was built as (CMake's PROJECT_VERSION),
// recorded in every result file.
#ifndef DWELLFIT_ESTIMATOR_COMMON_VERSION_H_
#define DWELLFIT_ESTIMATOR_COMMON_VERSION_H_

namespace dwellfit {

// "major.minor.patch", e.g. "0.1.0".
const char* DwellfitVersion();

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_VERSION_H_
