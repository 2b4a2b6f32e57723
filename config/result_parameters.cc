#include "dwellfit/config/result_parameters.h"

#include <cmath>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/text_file.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {

ParameterVector ReadResultParameters(const std::string& path) {
  const std::string text = ReadTextFile(path, "give the result.yaml an identify run wrote");
  YAML::Node document;
  try {
    document = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, "", "not YAML: " + e.msg);
  }
  const YAML::Node parameters = document.IsMap() ? document["parameters"] : YAML::Node();
  if (!parameters.IsMap()) {
    throw InputError(path, 0, "parameters",
                     "no parameters block; give the result.yaml an identify run wrote");
  }
  ParameterVector p{};
  for (int i = 0; i < kNumParameters; ++i) {
    const std::string field = std::string("parameters.") + ParameterName(i) + ".value";
    double number = NAN;
    int line = parameters.Mark().line + 1;
    try {  // yaml-cpp throws for a key of a node it could not build (InvalidNode)
      const YAML::Node entry = parameters[ParameterName(i)];
      if (entry.IsDefined()) line = entry.Mark().line + 1;
      const YAML::Node value = entry.IsMap() ? entry["value"] : YAML::Node();
      if (value.IsScalar()) number = value.as<double>();
    } catch (const YAML::Exception&) {
    }
    if (!std::isfinite(number)) {
      throw InputError(path, line, field,
                       "missing or not a finite number; the file must be a "
                       "result.yaml written by identify");
    }
    p[i] = number;
  }
  return p;
}

}  // namespace dwellfit
