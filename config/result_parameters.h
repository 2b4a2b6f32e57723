// Reading the identified parameters back from an identify run's result.yaml
// (docs/outputs.md): `parameters.<name>.value` for the six parameters, the
// natural frequency in rad/s.
#ifndef DWELLFIT_CONFIG_RESULT_PARAMETERS_H_
#define DWELLFIT_CONFIG_RESULT_PARAMETERS_H_

#include <string>

#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// Throws InputError naming the file, the line and the key for a file that
// cannot be read, is not YAML, or lacks a finite parameters.<name>.value.
ParameterVector ReadResultParameters(const std::string& path);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_RESULT_PARAMETERS_H_
