// Test support for config/: a fresh directory holding a config file and the
// data files it names.
#ifndef DWELLFIT_TESTS_CONFIG_TEST_SUPPORT_H_
#define DWELLFIT_TESTS_CONFIG_TEST_SUPPORT_H_

#include <filesystem>
#include <fstream>
#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "gtest/gtest.h"

namespace dwellfit {

// The thesis-numerical config of config/README.md (line numbers matter: the
// error tests name them).
inline constexpr char kValidConfig[] = R"(# line 1
data: sweeps.csv
fit: [F0.01, A41.5]
validate: [A41.2, A41.8/down]
initial_guess:
  eta_e: 130
  mu1: 0.26
  mu2: 390
  delta: 1.3e4
  alpha: 1.17e9
  omega_hz: 40
fixed: [omega]
stages: [algebraic, vertical]
residual:
  error: relative
  use_point_sigma: false
solver:
  max_iterations: 150
  function_tolerance: 1e-12
  gradient_tolerance: 1e-25
  parameter_tolerance: 1e-18
  num_threads: 2
jump_detection:
  min_ratio: 3.0
  min_relative_amplitude: 0.25
effective_nonlinearity_reference_hz: 41
output_dir: out/thesis-numerical
)";

// A directory under the test temp dir, unique per test, with an empty
// sweeps.csv; configs are written into it.
class ConfigDirectory {
 public:
  ConfigDirectory() {
    const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::path(testing::TempDir()) / "dwellfit_config" /
            (std::string(test->test_suite_name()) + "." + test->name());
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
    WriteFile("sweeps.csv", "sweep,direction,frequency_hz,a_base,amplitude\n");
  }

  // Writes `text` to `name` inside the directory; returns its path.
  std::string WriteFile(const std::string& name, const std::string& text) const {
    const std::filesystem::path file = path_ / name;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file) << text;
    return file.string();
  }
  std::string WriteConfig(const std::string& text) const {
    return WriteFile("identify.yaml", text);
  }

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Replaces the first occurrence of `from` in `text` (which must contain it).
inline std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::string::size_type at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The InputError `load` throws; fails the test when it throws none.
template <typename Load>
InputError ErrorOf(Load load) {
  try {
    load();
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError thrown";
  return InputError("none");
}

// The error of loading `text` written as the config of `dir` (at `*path`).
inline InputError LoadError(const ConfigDirectory& dir, const std::string& text,
                            std::string* path) {
  *path = dir.WriteConfig(text);
  return ErrorOf([&] { LoadIdentifyConfig(*path); });
}

}  // namespace dwellfit

#endif  // DWELLFIT_TESTS_CONFIG_TEST_SUPPORT_H_
