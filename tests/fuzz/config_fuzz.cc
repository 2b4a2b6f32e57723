// Fuzz bodies of the identify config (config/identify_config.h): a YAML file
// read by LoadIdentifyConfig, and `--set` values (config/config_override.h)
// applied to a complete config. Data files are only checked to exist, so the
// scratch directory holds an empty `sweeps.csv` for `data: sweeps.csv`.
//
// ConfigToYaml promises text that LoadIdentifyConfig accepts again; an
// accepted config must therefore print, read back, and print the same YAML
// tree again (comments, which name the source file, left aside).
#include <stdexcept>
#include <string>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "tests/fuzz/fuzz_targets.h"
#include "tests/fuzz/scratch_dir.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit::fuzz {
namespace {

// config/README.md's complete example: every block, so that overrides can
// meet each kind of value.
constexpr char kBaseConfig[] = R"(data: sweeps.csv
fit: [F0.01, A41.5]
validate: [A41.2, A41.8/down]
initial_guess: {eta_e: 130, mu1: 0.26, mu2: 390, delta: 1.3e4, alpha: 1.17e9, omega_hz: 40}
fixed: [omega]
stages: [algebraic, vertical]
residual: {error: absolute, use_point_sigma: true, amplitude_floor: 0}
solver:
  max_iterations: 200
  function_tolerance: 1e-8
  gradient_tolerance: 1e-30
  parameter_tolerance: 1e-20
  num_threads: 0
  nonmonotonic_steps: false
penalties:
  bifurcation_range:
    enabled: true
    exponent: 10
    weight: 1.0
    enforce: [frequency_jump_down, amplitude_jump_up]
  branch_stability: {enabled: false, lambda: 50, weight: 1.0}
multi_start: {starts: 1, spread: 3, seed: 1, threads: 2}
jump_detection:
  min_ratio: 1.07
  min_relative_amplitude: 0.2
  noise_multiple: 6
  min_candidate_steps: 5
jumps:
  - sweep: F0.01/down
    kind: jump_up
    between_hz: [40.7, 40.6]
  - sweep: A41.8/up
    none: true
effective_nonlinearity_reference_hz: 40
output_dir: out/thesis-numerical
)";

// The scratch directory with the data file the configs name.
void PrepareDataFile() {
  static const bool prepared = [] {
    WriteScratchFile("sweeps.csv", std::string("sweep,direction,freq_hz,a_base,a\n"));
    return true;
  }();
  (void)prepared;
}

// `text` as a YAML tree printed without comments.
std::string CommentFree(const std::string& text) {
  YAML::Emitter out;
  out << YAML::Load(text);
  return out.c_str();
}

void CheckPrintsAndReadsBack(const IdentifyConfig& config) {
  const std::string printed = ConfigToYaml(config);
  const std::string path = WriteScratchFile("printed.yaml", printed);
  std::string reprinted;
  try {
    reprinted = ConfigToYaml(LoadIdentifyConfig(path));
  } catch (const InputError& e) {
    throw std::logic_error(std::string("ConfigToYaml's text is rejected: ") + e.what() +
                           "\n--- printed:\n" + printed);
  }
  if (CommentFree(reprinted) != CommentFree(printed)) {
    throw std::logic_error("ConfigToYaml's text reads back as another config\n--- printed:\n" +
                           printed + "\n--- read back and printed:\n" + reprinted);
  }
}

// Loads the config at `path` with `overrides`; checks it when accepted.
void LoadAndCheck(const std::string& path, const std::vector<ConfigOverride>& overrides) {
  IdentifyConfig config;
  try {
    config = LoadIdentifyConfig(path, overrides);
  } catch (const InputError&) {
    return;
  }
  CheckPrintsAndReadsBack(config);
}

}  // namespace

void IdentifyConfigBody(const std::uint8_t* data, std::size_t size) {
  PrepareDataFile();
  LoadAndCheck(WriteScratchFile("identify.yaml", data, size), {});
}

void SetFlagBody(const std::uint8_t* data, std::size_t size) {
  PrepareDataFile();
  static const std::string base_path = WriteScratchFile("base.yaml", std::string(kBaseConfig));
  std::vector<ConfigOverride> overrides;
  try {
    overrides = ParseSetFlag(std::string(reinterpret_cast<const char*>(data), size), "--set");
  } catch (const InputError&) {
    return;
  }
  LoadAndCheck(base_path, overrides);
}

}  // namespace dwellfit::fuzz
