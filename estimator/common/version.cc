#include "dwellfit/estimator/common/version.h"

namespace dwellfit {

const char* DwellfitVersion() { return DWELLFIT_VERSION; }

}  // namespace dwellfit
