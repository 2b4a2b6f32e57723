#include "dwellfit/config/identify_config.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

std::vector<std::string> Names(const std::vector<SweepSelection>& selections) {
  std::vector<std::string> names;
  for (const SweepSelection& selection : selections) names.push_back(selection.Name());
  return names;
}

// The InputError LoadIdentifyConfig throws; fails the test when it throws none.
InputError LoadError(const std::string& path) {
  return ErrorOf([&] { LoadIdentifyConfig(path); });
}

// The error of loading kValidConfig with `from` replaced by `to`.
InputError ErrorWith(const ConfigDirectory& dir, const std::string& from, const std::string& to,
                     std::string* path) {
  *path = dir.WriteConfig(Replace(kValidConfig, from, to));
  return LoadError(*path);
}

// The message names the file, the 1-based line and the key path.
void ExpectAt(const InputError& error, const std::string& path, int line, const std::string& key) {
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), line);
  EXPECT_EQ(error.field(), key);
  EXPECT_THAT(error.what(), HasSubstr(path + ":" + std::to_string(line) + ": "));
  EXPECT_THAT(error.what(), HasSubstr("'" + key + "'"));
}

TEST(LoadIdentifyConfig, ValidConfigLandsInTheStructs) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(kValidConfig);
  const IdentifyConfig config = LoadIdentifyConfig(path);

  EXPECT_EQ(config.config_path, path);
  EXPECT_THAT(config.data_files, ElementsAre((dir.path() / "sweeps.csv").string()));
  EXPECT_THAT(Names(config.fit_sweeps), ElementsAre("F0.01", "A41.5"));
  EXPECT_THAT(Names(config.validate_sweeps), ElementsAre("A41.2", "A41.8/down"));
  EXPECT_FALSE(config.fit_sweeps[0].direction.has_value());
  EXPECT_EQ(config.validate_sweeps[1].sweep_id, "A41.8");
  EXPECT_EQ(config.validate_sweeps[1].direction, SweepDirection::kDown);

  const IdentificationOptions& options = config.identification;
  EXPECT_EQ(options.initial[kEtaE], 130.0);
  EXPECT_EQ(options.initial[kMu1], 0.26);
  EXPECT_EQ(options.initial[kMu2], 390.0);
  EXPECT_EQ(options.initial[kDelta], 1.3e4);
  EXPECT_EQ(options.initial[kAlpha], 1.17e9);
  EXPECT_DOUBLE_EQ(options.initial[kNaturalFrequency], 2.0 * M_PI * 40.0);  // Hz -> rad/s
  EXPECT_THAT(options.fixed, ElementsAre(false, false, false, false, false, true));
  EXPECT_THAT(options.solve.stages, ElementsAre(ResidualKind::kAlgebraic, ResidualKind::kVertical));
  EXPECT_EQ(options.solve.residual.error, ErrorMeasure::kRelative);
  EXPECT_FALSE(options.solve.residual.use_point_sigma);
  EXPECT_EQ(options.solve.solver.max_iterations, 150);
  EXPECT_EQ(options.solve.solver.function_tolerance, 1e-12);
  EXPECT_EQ(options.solve.solver.gradient_tolerance, 1e-25);
  EXPECT_EQ(options.solve.solver.parameter_tolerance, 1e-18);
  EXPECT_EQ(options.solve.solver.num_threads, 2);
  EXPECT_EQ(config.jump_detection.min_ratio, 3.0);
  EXPECT_EQ(config.jump_detection.min_relative_amplitude, 0.25);
  ASSERT_TRUE(config.omega_ref_rad_s.has_value());
  EXPECT_DOUBLE_EQ(*config.omega_ref_rad_s, 2.0 * M_PI * 41.0);
  EXPECT_EQ(config.output_dir, (dir.path() / "out" / "thesis-numerical").string());
  EXPECT_TRUE(config.overrides.empty());
}

// The defaults of config/README.md's tables, written here rather than read
// from the options structs, so a changed default fails until the
// documentation changes with it.
TEST(LoadIdentifyConfig, OptionalKeysTakeTheDocumentedDefaults) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(R"(data: sweeps.csv
fit: [F0.01/up]
initial_guess: {eta_e: 100, mu1: 0.2, mu2: 300, delta: 1e4, alpha: 9e8, omega_hz: 40}
output_dir: out
)");
  const IdentifyConfig config = LoadIdentifyConfig(path);
  const IdentificationOptions& options = config.identification;
  EXPECT_EQ(config.fit_sweeps[0].direction, SweepDirection::kUp);
  EXPECT_TRUE(config.validate_sweeps.empty());
  for (int i = 0; i < kNumParameters; ++i) EXPECT_FALSE(options.fixed[i]) << i;  // all free
  EXPECT_THAT(options.solve.stages, ElementsAre(ResidualKind::kAlgebraic, ResidualKind::kVertical));
  EXPECT_EQ(options.solve.residual.error, ErrorMeasure::kAbsolute);
  EXPECT_TRUE(options.solve.residual.use_point_sigma);
  EXPECT_EQ(options.solve.residual.amplitude_floor, 0.0);
  EXPECT_EQ(options.solve.solver.max_iterations, 200);
  EXPECT_EQ(options.solve.solver.function_tolerance, 1e-8);
  EXPECT_EQ(options.solve.solver.start_function_tolerance, 1e-5);
  EXPECT_EQ(options.solve.solver.gradient_tolerance, 1e-30);
  EXPECT_EQ(options.solve.solver.parameter_tolerance, 1e-20);
  EXPECT_EQ(options.solve.solver.num_threads, 0);
  EXPECT_FALSE(options.solve.solver.nonmonotonic_steps);
  EXPECT_TRUE(options.solve.solver.valley_polish);
  EXPECT_EQ(config.multi_start.starts, 1);
  EXPECT_EQ(config.multi_start.spread, 3.0);
  EXPECT_EQ(config.multi_start.seed, 1u);
  EXPECT_EQ(config.multi_start.threads, 2);
  EXPECT_EQ(config.jump_detection.min_ratio, 1.07);
  EXPECT_EQ(config.jump_detection.min_relative_amplitude, 0.2);
  EXPECT_EQ(config.jump_detection.noise_multiple, 6.0);
  EXPECT_EQ(config.jump_detection.min_candidate_steps, 5);
  EXPECT_TRUE(config.jump_overrides.empty());
  EXPECT_FALSE(config.omega_ref_rad_s.has_value());
  EXPECT_FALSE(config.model_selection.has_value());
}

TEST(LoadIdentifyConfig, PathsAreRelativeToTheConfigFileNotTheWorkingDirectory) {
  const ConfigDirectory dir;
  dir.WriteFile("data/run1.csv", "");
  dir.WriteFile("data/run2.csv", "");
  const std::string path =
      dir.WriteFile("configs/identify.yaml", R"(data: [../data/run1.csv, ../data/run2.csv]
fit: [F1]
initial_guess: {eta_e: 100, mu1: 0.2, mu2: 300, delta: 1e4, alpha: 9e8, omega_hz: 40}
output_dir: ../out
)");
  const fs::path working_directory = fs::current_path();
  fs::current_path(fs::temp_directory_path());
  const IdentifyConfig config = LoadIdentifyConfig(path);
  fs::current_path(working_directory);
  EXPECT_THAT(config.data_files, ElementsAre((dir.path() / "data" / "run1.csv").string(),
                                             (dir.path() / "data" / "run2.csv").string()));
  EXPECT_EQ(config.output_dir, (dir.path() / "out").string());
}

TEST(ConfigToYaml, RoundTripsThroughLoadIdentifyConfig) {
  const ConfigDirectory dir;
  const IdentifyConfig loaded = LoadIdentifyConfig(dir.WriteConfig(kValidConfig));
  const std::string yaml = ConfigToYaml(loaded);
  const IdentifyConfig reloaded = LoadIdentifyConfig(dir.WriteFile("in_effect.yaml", yaml));

  EXPECT_EQ(reloaded.data_files, loaded.data_files);
  EXPECT_EQ(Names(reloaded.fit_sweeps), Names(loaded.fit_sweeps));
  EXPECT_EQ(Names(reloaded.validate_sweeps), Names(loaded.validate_sweeps));
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_DOUBLE_EQ(reloaded.identification.initial[i], loaded.identification.initial[i])
        << ParameterName(i);
  }
  EXPECT_EQ(reloaded.identification.fixed, loaded.identification.fixed);
  EXPECT_EQ(reloaded.identification.solve.stages, loaded.identification.solve.stages);
  EXPECT_EQ(reloaded.identification.solve.residual.error,
            loaded.identification.solve.residual.error);
  EXPECT_EQ(reloaded.identification.solve.residual.use_point_sigma,
            loaded.identification.solve.residual.use_point_sigma);
  EXPECT_EQ(reloaded.identification.solve.solver.max_iterations,
            loaded.identification.solve.solver.max_iterations);
  EXPECT_EQ(reloaded.identification.solve.solver.gradient_tolerance,
            loaded.identification.solve.solver.gradient_tolerance);
  EXPECT_EQ(reloaded.identification.solve.solver.num_threads,
            loaded.identification.solve.solver.num_threads);
  EXPECT_EQ(reloaded.jump_detection.min_relative_amplitude,
            loaded.jump_detection.min_relative_amplitude);
  EXPECT_DOUBLE_EQ(*reloaded.omega_ref_rad_s, *loaded.omega_ref_rad_s);
  EXPECT_EQ(reloaded.output_dir, loaded.output_dir);
}

// The start stage's tolerance: read, shown in the configuration in effect,
// and its default where the config is silent.
TEST(LoadIdentifyConfig, StartFunctionToleranceIsReadAndShown) {
  const ConfigDirectory dir;
  std::string text = kValidConfig;
  const std::string line = "  function_tolerance: 1e-12\n";
  ASSERT_NE(text.find(line), std::string::npos);
  const std::string path = dir.WriteConfig(text);
  EXPECT_EQ(LoadIdentifyConfig(path).identification.solve.solver.start_function_tolerance,
            1e-5);  // config/README.md's default
  text.replace(text.find(line), line.size(), line + "  start_function_tolerance: 1e-3\n");
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(text));
  EXPECT_EQ(config.identification.solve.solver.start_function_tolerance, 1e-3);
  EXPECT_THAT(ConfigToYaml(config), HasSubstr("start_function_tolerance: 0.001"));
}

// units: and plot: name the data's units and the figures' amplitude axis;
// unstated they are empty and off, and neither is shown; a bad entry names
// its key and line.
TEST(LoadIdentifyConfig, UnitsAndPlotAreReadAndShown) {
  const ConfigDirectory dir;
  const IdentifyConfig by_default = LoadIdentifyConfig(dir.WriteConfig(kValidConfig));
  EXPECT_TRUE(by_default.units.a.empty());
  EXPECT_FALSE(by_default.log_amplitude);
  EXPECT_THAT(ConfigToYaml(by_default), Not(HasSubstr("units")));
  const IdentifyConfig stated = LoadIdentifyConfig(dir.WriteConfig(
      std::string(kValidConfig) + "units: {a: mm, a_base: g}\nplot: {log_amplitude: true}\n"));
  EXPECT_EQ(stated.units.a, "mm");
  EXPECT_EQ(stated.units.a_base, "g");
  EXPECT_TRUE(stated.log_amplitude);
  const IdentifyConfig reloaded = LoadIdentifyConfig(dir.WriteConfig(ConfigToYaml(stated)));
  EXPECT_EQ(reloaded.units.a, "mm");
  EXPECT_TRUE(reloaded.log_amplitude);
  std::string path;
  const InputError unknown =
      LoadError(dir, std::string(kValidConfig) + "units: {amplitude: mm}\n", &path);
  EXPECT_THAT(unknown.what(), HasSubstr("amplitude"));
  const InputError not_bool =
      LoadError(dir, std::string(kValidConfig) + "plot: {log_amplitude: maybe}\n", &path);
  EXPECT_THAT(not_bool.what(), HasSubstr("log_amplitude"));
}

// The forcing calibration's block: unset and not shown by default; read,
// shown and read back when given; an invalid prior or dwell choice names its
// key.
TEST(LoadIdentifyConfig, ForcingCalibrationIsReadAndShown) {
  const ConfigDirectory dir;
  const IdentifyConfig by_default = LoadIdentifyConfig(dir.WriteConfig(kValidConfig));
  std::string path_first;
  EXPECT_FALSE(by_default.forcing_calibration.has_value());
  EXPECT_THAT(ConfigToYaml(by_default), Not(HasSubstr("forcing_calibration")));
  const IdentifyConfig stated = LoadIdentifyConfig(dir.WriteConfig(
      std::string(kValidConfig) +
      "forcing_calibration: {prior_sigma: 0.02, held_out_dwells: below_half_peak, parameter: "
      "omega}\n"));
  ASSERT_TRUE(stated.forcing_calibration.has_value());
  EXPECT_EQ(stated.forcing_calibration->prior_sigma, 0.02);
  EXPECT_EQ(stated.forcing_calibration->held_out_dwells, HeldOutDwells::kBelowHalfPeak);
  EXPECT_EQ(stated.forcing_calibration->parameter, CalibratedParameter::kNaturalFrequency);
  const IdentifyConfig reloaded = LoadIdentifyConfig(dir.WriteConfig(ConfigToYaml(stated)));
  ASSERT_TRUE(reloaded.forcing_calibration.has_value());
  EXPECT_EQ(reloaded.forcing_calibration->prior_sigma, 0.02);
  EXPECT_EQ(reloaded.forcing_calibration->held_out_dwells, HeldOutDwells::kBelowHalfPeak);
  EXPECT_EQ(reloaded.forcing_calibration->parameter, CalibratedParameter::kNaturalFrequency);
  const InputError parameter = LoadError(
      dir, std::string(kValidConfig) + "forcing_calibration: {parameter: mu1}\n", &path_first);
  EXPECT_THAT(parameter.what(), HasSubstr("give eta_e (the forcing) or omega"));
  std::string path;
  const InputError negative =
      LoadError(dir, std::string(kValidConfig) + "forcing_calibration: {prior_sigma: -1}\n", &path);
  EXPECT_THAT(negative.what(), HasSubstr("prior_sigma must lie in (0, 1]"));
  const InputError choice = LoadError(
      dir, std::string(kValidConfig) + "forcing_calibration: {held_out_dwells: all}\n", &path);
  EXPECT_THAT(choice.what(), HasSubstr("held_out_dwells"));
}

// The valley polish: on by default, off when the config says so, shown in
// the configuration in effect; a value that is not a bool names its line.
TEST(LoadIdentifyConfig, ValleyPolishIsReadAndShown) {
  const ConfigDirectory dir;
  const std::string line = "  max_iterations: 150\n";
  ASSERT_NE(std::string(kValidConfig).find(line), std::string::npos);
  const IdentifyConfig by_default = LoadIdentifyConfig(dir.WriteConfig(kValidConfig));
  EXPECT_TRUE(by_default.identification.solve.solver.valley_polish);
  EXPECT_THAT(ConfigToYaml(by_default), HasSubstr("valley_polish: true"));
  const IdentifyConfig off = LoadIdentifyConfig(
      dir.WriteConfig(Replace(kValidConfig, line, line + "  valley_polish: false\n")));
  EXPECT_FALSE(off.identification.solve.solver.valley_polish);
  EXPECT_THAT(ConfigToYaml(off), HasSubstr("valley_polish: false"));
  std::string path;
  const InputError error = ErrorWith(dir, line, line + "  valley_polish: sometimes\n", &path);
  ExpectAt(error, path, 19, "solver.valley_polish");
}

TEST(ConfigToYaml, ShowsTheSourceFileAndOmegaInHz) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(kValidConfig);
  const std::string yaml = ConfigToYaml(LoadIdentifyConfig(path));
  EXPECT_THAT(yaml, HasSubstr("# Configuration in effect, loaded from " + path));
  EXPECT_THAT(yaml, HasSubstr("omega_hz: 40"));
  EXPECT_THAT(yaml, HasSubstr("alpha: 1.17e+09"));
  EXPECT_THAT(yaml, HasSubstr("function_tolerance: 1e-12"));
  EXPECT_THAT(yaml, HasSubstr("effective_nonlinearity_reference_hz: 41"));
  EXPECT_THAT(yaml, HasSubstr("fixed: [omega]"));
}

// The first ```yaml block of config/README.md.
std::string ReadmeExample() {
  std::ifstream readme(std::string(DWELLFIT_SOURCE_DIR) + "/config/README.md");
  std::stringstream text;
  text << readme.rdbuf();
  const std::string all = text.str();
  const std::string open = "```yaml\n";
  const std::string::size_type begin = all.find(open);
  EXPECT_NE(begin, std::string::npos);
  const std::string::size_type end = all.find("```", begin + open.size());
  return all.substr(begin + open.size(), end - begin - open.size());
}

TEST(ConfigReadme, AnnotatedExampleLoads) {
  const ConfigDirectory dir;
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(ReadmeExample()));
  EXPECT_THAT(Names(config.fit_sweeps), ElementsAre("F0.01", "A41.5"));
  EXPECT_DOUBLE_EQ(config.identification.initial[kNaturalFrequency], HzToRadPerSecond(40.0));
  EXPECT_EQ(config.identification.solve.solver.max_iterations, 200);
  EXPECT_TRUE(config.identification.solve.penalties.bifurcation_range.enabled);
  EXPECT_FALSE(config.identification.solve.penalties.branch_stability.enabled);
  // The example spells out the jump-detection defaults of the README's table.
  EXPECT_EQ(config.jump_detection.min_ratio, 1.07);
  EXPECT_EQ(config.jump_detection.min_relative_amplitude, 0.2);
  EXPECT_EQ(config.jump_detection.noise_multiple, 6.0);
  EXPECT_EQ(config.jump_detection.min_candidate_steps, 5);
  ASSERT_EQ(config.jump_overrides.size(), 2u);
  EXPECT_EQ(config.jump_overrides[0].sweep, "F0.01/down");
  EXPECT_TRUE(config.jump_overrides[1].none);
  EXPECT_EQ(config.output_dir, (dir.path() / "out" / "thesis-numerical").string());
}

TEST(IdentifyConfigErrors, UnknownKeyInABlockNamesKeyLineAndAllowedKeys) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "  max_iterations: 150", "  max_iteration: 150", &path);
  ExpectAt(error, path, 18, "solver.max_iteration");
  EXPECT_THAT(error.what(), HasSubstr("unknown key 'max_iteration' in 'solver'"));
  EXPECT_THAT(error.what(), HasSubstr("did you mean 'max_iterations'?"));
  EXPECT_THAT(error.what(),
              HasSubstr("allowed: max_iterations, function_tolerance, start_function_tolerance, "
                        "gradient_tolerance, parameter_tolerance, num_threads"));
}

TEST(IdentifyConfigErrors, UnknownTopLevelKeyListsTheTopLevelKeys) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "output_dir:", "ouput_dir:", &path);
  ExpectAt(error, path, 27, "ouput_dir");
  EXPECT_THAT(error.what(), HasSubstr("unknown key 'ouput_dir' at the top level (did you mean "
                                      "'output_dir'?); allowed: data, fit, validate,"));
}

TEST(IdentifyConfigErrors, RepeatedKeyNamesBothLines) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "  mu2: 390", "  mu2: 390\n  mu1: 0.3", &path);
  ExpectAt(error, path, 9, "initial_guess.mu1");
  EXPECT_THAT(error.what(), HasSubstr("appears twice in 'initial_guess' (first at line 7)"));
}

TEST(IdentifyConfigErrors, FractionForAnIntegerFieldIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "  max_iterations: 150", "  max_iterations: 2.5", &path);
  ExpectAt(error, path, 18, "solver.max_iterations");
  EXPECT_THAT(error.what(), HasSubstr("expected a whole number (e.g. 200), got '2.5'"));
}

TEST(IdentifyConfigErrors, TextForANumberIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "  mu1: 0.26", "  mu1: 0,26", &path);
  ExpectAt(error, path, 7, "initial_guess.mu1");
  EXPECT_THAT(error.what(), HasSubstr("expected a number"));
  EXPECT_THAT(error.what(), HasSubstr("got '0,26'"));
}

TEST(IdentifyConfigErrors, ValueWhereABlockIsExpectedIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error =
      ErrorWith(dir, "jump_detection:\n  min_ratio: 3.0\n  min_relative_amplitude: 0.25",
                "jump_detection: 3.0", &path);
  ExpectAt(error, path, 23, "jump_detection");
  EXPECT_THAT(error.what(), HasSubstr("expected a block of keys (min_ratio, "
                                      "min_relative_amplitude, noise_multiple, "
                                      "min_candidate_steps), got a single value"));
}

TEST(LoadIdentifyConfig, LeftOutOrAutoInitialGuessesAreFoundFromTheData) {
  const ConfigDirectory dir;
  const IdentifyConfig left_out =
      LoadIdentifyConfig(dir.WriteConfig(Replace(kValidConfig, "  mu2: 390\n", "")));
  EXPECT_FALSE(left_out.initial_guess[kMu2].has_value());
  EXPECT_TRUE(left_out.initial_guess[kMu1].has_value());
  const IdentifyConfig automatic =
      LoadIdentifyConfig(dir.WriteConfig(Replace(kValidConfig, "  mu2: 390\n", "  mu2: auto\n")));
  EXPECT_FALSE(automatic.initial_guess[kMu2].has_value());
  // The printed config says so, and reads back the same.
  EXPECT_THAT(ConfigToYaml(automatic), HasSubstr("mu2: auto"));
}

TEST(IdentifyConfigErrors, AnInitialGuessThatIsNeitherANumberNorAutoIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "  mu2: 390\n", "  mu2: automatic\n", &path);
  ExpectAt(error, path, 8, "initial_guess.mu2");
  EXPECT_THAT(error.what(), HasSubstr("expected a number"));
}

TEST(IdentifyConfigErrors, MissingTopLevelKeyNamesFileAndKey) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "output_dir: out/thesis-numerical\n", "", &path);
  EXPECT_EQ(error.line(), 0);  // a missing key has no line
  EXPECT_THAT(error.what(), HasSubstr(path + ": field 'output_dir': missing required key "
                                             "'output_dir' at the top level"));
}

TEST(IdentifyConfigErrors, NonPositiveEtaEAndNaturalFrequencyAreErrors) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = ErrorWith(dir, "eta_e: 130", "eta_e: -130", &path);
  ExpectAt(error, path, 6, "initial_guess.eta_e");
  EXPECT_THAT(error.what(), HasSubstr("must be positive, got -130"));
  error = ErrorWith(dir, "omega_hz: 40", "omega_hz: 0", &path);
  ExpectAt(error, path, 11, "initial_guess.omega_hz");
}

TEST(IdentifyConfigErrors, NegativeDampingIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "mu2: 390", "mu2: -1", &path);
  ExpectAt(error, path, 8, "initial_guess.mu2");
  EXPECT_THAT(error.what(), HasSubstr("must be non-negative"));
}

TEST(IdentifyConfigErrors, SweepListedTwiceInFit) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error =
      ErrorWith(dir, "fit: [F0.01, A41.5]", "fit:\n  - F0.01\n  - F0.01", &path);
  ExpectAt(error, path, 5, "fit");
  EXPECT_THAT(error.what(), HasSubstr("sweep 'F0.01' is listed twice (first at line 4)"));
}

TEST(IdentifyConfigErrors, SweepIdAndOneOfItsDirectionsOverlap) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "fit: [F0.01, A41.5]", "fit: [F0.01, F0.01/up]", &path);
  ExpectAt(error, path, 3, "fit");
  EXPECT_THAT(error.what(), HasSubstr("sweep 'F0.01/up' overlaps 'F0.01'"));
}

TEST(IdentifyConfigErrors, SweepBothFittedAndValidatedIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error =
      ErrorWith(dir, "validate: [A41.2, A41.8/down]", "validate: [A41.2, A41.5/down]", &path);
  ExpectAt(error, path, 4, "validate");
  EXPECT_THAT(error.what(), HasSubstr("sweep 'A41.5/down' is also fitted ('A41.5' in 'fit' at "
                                      "line 3)"));
}

TEST(IdentifyConfigErrors, OppositeDirectionsMayBeFittedAndValidated) {
  const ConfigDirectory dir;
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(
      Replace(Replace(kValidConfig, "fit: [F0.01, A41.5]", "fit: [F0.01, A41.5/up]"),
              "validate: [A41.2, A41.8/down]", "validate: [A41.5/down]")));
  EXPECT_THAT(Names(config.validate_sweeps), ElementsAre("A41.5/down"));
}

TEST(IdentifyConfigErrors, UnknownSweepDirection) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "A41.5]", "A41.5/sideways]", &path);
  ExpectAt(error, path, 3, "fit");
  EXPECT_THAT(error.what(), HasSubstr("has direction 'sideways'; write 'A41.5' for both "
                                      "directions, or 'A41.5/up' or 'A41.5/down' for one"));
}

TEST(IdentifyConfigErrors, EmptyFitIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "fit: [F0.01, A41.5]", "fit: []", &path);
  ExpectAt(error, path, 3, "fit");
  EXPECT_THAT(error.what(), HasSubstr("lists no sweep"));
}

TEST(IdentifyConfigErrors, UnknownFixedParameterListsTheParameters) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "fixed: [omega]", "fixed: [delta, omega_hz]", &path);
  ExpectAt(error, path, 12, "fixed");
  EXPECT_THAT(error.what(), HasSubstr("unknown parameter 'omega_hz' (the parameter is called "
                                      "'omega'); allowed: eta_e, mu1, mu2, delta, alpha, omega"));
}

TEST(IdentifyConfigErrors, UnknownOrNoStage) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = ErrorWith(dir, "stages: [algebraic, vertical]", "stages: [algebriac]", &path);
  ExpectAt(error, path, 13, "stages");
  EXPECT_THAT(error.what(), HasSubstr("unknown stage 'algebriac' (did you mean 'algebraic'?)"));
  error = ErrorWith(dir, "stages: [algebraic, vertical]", "stages: []", &path);
  ExpectAt(error, path, 13, "stages");
  EXPECT_THAT(error.what(), HasSubstr("lists no stage"));
}

TEST(IdentifyConfigErrors, UnknownErrorMeasureAndNonBooleanSigmaSwitch) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = ErrorWith(dir, "error: relative", "error: logarithmic", &path);
  ExpectAt(error, path, 15, "residual.error");
  EXPECT_THAT(error.what(), HasSubstr("allowed: absolute, relative"));
  error = ErrorWith(dir, "use_point_sigma: false", "use_point_sigma: 0.5", &path);
  ExpectAt(error, path, 16, "residual.use_point_sigma");
  EXPECT_THAT(error.what(), HasSubstr("expected true or false, got '0.5'"));
}

TEST(IdentifyConfigErrors, InvalidSolverSettingsAreReportedAtTheSolverBlock) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "max_iterations: 150", "max_iterations: 0", &path);
  ExpectAt(error, path, 17, "solver");
  EXPECT_THAT(error.what(), HasSubstr("solver.max_iterations must be at least 1"));
}

TEST(IdentifyConfigErrors, InvalidJumpDetectionIsReportedAtItsBlock) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "min_ratio: 3.0", "min_ratio: 0.5", &path);
  ExpectAt(error, path, 23, "jump_detection");
  EXPECT_THAT(error.what(), HasSubstr("jump_detection.min_ratio must be greater than 1"));
}

TEST(LoadIdentifyConfig, JumpDetectionNoiseTestKeys) {
  const ConfigDirectory dir;
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(
      Replace(kValidConfig, "  min_relative_amplitude: 0.25",
              "  min_relative_amplitude: 0.25\n  noise_multiple: 4.5\n  min_candidate_steps: 8")));
  EXPECT_EQ(config.jump_detection.noise_multiple, 4.5);
  EXPECT_EQ(config.jump_detection.min_candidate_steps, 8);
  const IdentifyConfig reloaded =
      LoadIdentifyConfig(dir.WriteFile("in_effect.yaml", ConfigToYaml(config)));
  EXPECT_EQ(reloaded.jump_detection.min_ratio, 3.0);
  EXPECT_EQ(reloaded.jump_detection.noise_multiple, 4.5);
  EXPECT_EQ(reloaded.jump_detection.min_candidate_steps, 8);
}

TEST(IdentifyConfigErrors, InvalidNoiseTestSettingsAreReportedAtTheJumpDetectionBlock) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = ErrorWith(dir, "  min_relative_amplitude: 0.25",
                               "  min_relative_amplitude: 0.25\n  noise_multiple: -1", &path);
  ExpectAt(error, path, 23, "jump_detection");
  EXPECT_THAT(error.what(), HasSubstr("jump_detection.noise_multiple must be a non-negative "
                                      "number (0: no noise test)"));
  error = ErrorWith(dir, "  min_relative_amplitude: 0.25",
                    "  min_relative_amplitude: 0.25\n  min_candidate_steps: 0", &path);
  ExpectAt(error, path, 23, "jump_detection");
  EXPECT_THAT(error.what(), HasSubstr("jump_detection.min_candidate_steps must be at least 1"));
  error = ErrorWith(dir, "  min_relative_amplitude: 0.25",
                    "  min_relative_amplitude: 0.25\n  min_candidate_steps: 5.5", &path);
  ExpectAt(error, path, 26, "jump_detection.min_candidate_steps");
}

TEST(IdentifyConfigErrors, MissingDataFileSaysWhereItLooked) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error =
      ErrorWith(dir, "data: sweeps.csv", "data: [sweeps.csv, nope.csv]", &path);
  ExpectAt(error, path, 2, "data");
  EXPECT_THAT(error.what(),
              HasSubstr("data file 'nope.csv' not found at " + (dir.path() / "nope.csv").string()));
  EXPECT_THAT(error.what(), HasSubstr("relative to the config file's directory"));
}

TEST(IdentifyConfigErrors, NonPositiveReferenceFrequency) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "effective_nonlinearity_reference_hz: 41",
                                     "effective_nonlinearity_reference_hz: -41", &path);
  ExpectAt(error, path, 26, "effective_nonlinearity_reference_hz");
  EXPECT_THAT(error.what(), HasSubstr("must be a positive frequency in Hz"));
}

// Finite in Hz but infinite in rad/s: the printed config would read "inf".
TEST(IdentifyConfigErrors, ReferenceFrequencyOverflowingInRadPerSecond) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "effective_nonlinearity_reference_hz: 41",
                                     "effective_nonlinearity_reference_hz: 1e308", &path);
  ExpectAt(error, path, 26, "effective_nonlinearity_reference_hz");
  EXPECT_THAT(error.what(), HasSubstr("the frequency 1e+308 Hz is too large (infinite in rad/s)"));
}

TEST(IdentifyConfigErrors, YamlSyntaxErrorHasItsLine) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = ErrorWith(dir, "fixed: [omega]", "fixed: [omega", &path);
  EXPECT_EQ(error.file(), path);
  EXPECT_GE(error.line(), 12);
  EXPECT_THAT(error.what(), HasSubstr("YAML syntax error"));
}

TEST(IdentifyConfigErrors, MissingConfigFile) {
  const ConfigDirectory dir;
  const std::string path = (dir.path() / "absent.yaml").string();
  const InputError error = LoadError(path);
  EXPECT_EQ(error.file(), path);
  EXPECT_THAT(error.what(), HasSubstr("no such file; give the path of the YAML config file"));
}

// Hostile configs (the config rows of the Hardening issue's table).

TEST(IdentifyConfigErrors, ASecondYamlDocumentIsAnErrorAtItsLine) {
  // Before: the second document was silently ignored.
  const ConfigDirectory dir;
  std::string path;
  const InputError error =
      LoadError(dir, std::string(kValidConfig) + "---\nfixed: [delta]\n", &path);
  EXPECT_EQ(std::string(error.what()),
            path +
                ":29: a second YAML document starts here (after a '---' line), and only the "
                "first would be read; the file holds one document: move these keys into the "
                "first one, or remove the '---' line");
  // A leading '---', and an empty document after a trailing one, hold nothing more.
  EXPECT_NO_THROW(LoadIdentifyConfig(
      dir.WriteConfig("---\n" + std::string(kValidConfig) + "---\n# nothing here\n")));
}

TEST(IdentifyConfigErrors, ASecondYamlDocumentInAPlanFileIsAnError) {
  const ConfigDirectory dir;
  const std::string plan = dir.WriteFile("plan.yaml", "output: out.csv\n---\noutput: other.csv\n");
  const InputError error = ErrorOf([&] { ReadDwellPlan(plan); });
  EXPECT_EQ(error.file(), plan);
  EXPECT_EQ(error.line(), 3);
  EXPECT_THAT(error.what(), HasSubstr("a second YAML document starts here"));
}

TEST(IdentifyConfigErrors, AFixedParameterWithoutAnInitialGuessIsAnError) {
  // Before: held at the automatic guess, unflagged.
  const ConfigDirectory dir;
  std::string path;
  InputError error = ErrorWith(dir, "  omega_hz: 40\n", "", &path);
  ExpectAt(error, path, 11, "fixed");
  EXPECT_THAT(error.what(),
              HasSubstr("parameter 'omega' is fixed but has no initial guess, and a fixed "
                        "parameter is held at the value the config gives: add "
                        "initial_guess.omega_hz (on the command line: --set "
                        "initial_guess.omega_hz=VALUE), or do not fix 'omega'"));
  path = dir.WriteConfig(Replace(Replace(kValidConfig, "  delta: 1.3e4", "  delta: auto"),
                                 "fixed: [omega]", "fixed: [omega, delta]"));
  error = LoadError(path);
  ExpectAt(error, path, 12, "fixed");
  EXPECT_THAT(error.what(), HasSubstr("add initial_guess.delta (on the command line: --set "
                                      "initial_guess.delta=VALUE), or do not fix 'delta'"));
}

TEST(IdentifyConfigErrors, TenThousandNestedListsSayTheYamlIsNestedTooDeeply) {
  // Before: "YAML syntax error: bad file".
  const ConfigDirectory dir;
  std::string path;
  const InputError error =
      LoadError(dir,
                std::string(kValidConfig) + "jumps: " + std::string(10000, '[') +
                    std::string(10000, ']') + "\n",
                &path);
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), 28);
  EXPECT_THAT(error.what(), HasSubstr("the YAML is nested too deeply"));
  EXPECT_THAT(error.what(), HasSubstr("look for runaway brackets or indentation here"));
}

TEST(IdentifyConfigErrors, MultiStartStartsAreBounded) {
  // Before: 2147483647 starts ran for hours.
  const ConfigDirectory dir;
  std::string path;
  const InputError error =
      ErrorWith(dir, "output_dir:", "multi_start:\n  starts: 2147483647\noutput_dir:", &path);
  ExpectAt(error, path, 27, "multi_start");
  EXPECT_THAT(error.what(),
              HasSubstr("multi_start.starts must be from 1 to 1000 (each start is a whole fit)"));
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(
      Replace(kValidConfig, "output_dir:", "multi_start: {starts: 1000}\noutput_dir:")));
  EXPECT_EQ(config.multi_start.starts, 1000);
  const InputError too_big =
      ErrorWith(dir, "  max_iterations: 150", "  max_iterations: 99999999999", &path);
  ExpectAt(too_big, path, 18, "solver.max_iterations");
  EXPECT_THAT(too_big.what(), HasSubstr("expected a whole number (e.g. 200), got '99999999999'"));
}

TEST(IdentifyConfigErrors, ADataPathThatIsADirectoryOrADeviceSaysWhatItIs) {
  // Before: "not found".
  const ConfigDirectory dir;
  std::string path;
  fs::create_directories(dir.path() / "sweeps_dir");
  InputError error = ErrorWith(dir, "data: sweeps.csv", "data: sweeps_dir", &path);
  ExpectAt(error, path, 2, "data");
  EXPECT_THAT(error.what(),
              HasSubstr("data file 'sweeps_dir' at " + (dir.path() / "sweeps_dir").string() +
                        " is a directory; give the path of a sweeps CSV file"));
  error = ErrorWith(dir, "data: sweeps.csv", "data: /dev/null", &path);
  EXPECT_THAT(error.what(), HasSubstr("data file '/dev/null' at /dev/null is a character "
                                      "device, not a file; give the path of a sweeps CSV file"));
}

TEST(IdentifyConfigErrors, BillionLaughsAliasesFailFastAtTheFirstWrongType) {
  // Nine levels of ten aliases each: 10^9 leaves if expanded; yaml-cpp shares
  // the nodes and the reader stops at the first value of the wrong type.
  std::string laughs = "&a0 [lol]";
  for (int i = 1; i <= 9; ++i) {
    laughs += ", &a" + std::to_string(i) + " [";
    for (int j = 0; j < 10; ++j)
      laughs += std::string(j > 0 ? ", " : "") + "*a" + std::to_string(i - 1);
    laughs += "]";
  }
  const ConfigDirectory dir;
  std::string path;
  InputError error = LoadError(dir, "laughs: [" + laughs + "]\n" + kValidConfig, &path);
  ExpectAt(error, path, 1, "laughs");
  EXPECT_THAT(error.what(), HasSubstr("unknown key 'laughs' at the top level"));
  error = LoadError(dir, std::string(kValidConfig) + "jumps: [" + laughs + "]\n", &path);
  ExpectAt(error, path, 28, "jumps[0]");
  EXPECT_THAT(error.what(), HasSubstr("expected a block of keys (sweep, kind, between_hz, "
                                      "between_a_base, none), got a list"));
}

TEST(IdentifyConfigErrors, ControlBytesAreEscapedInMessages) {
  const ConfigDirectory dir;
  std::string path;
  InputError error =
      ErrorWith(dir, "  max_iterations: 150", "  max_iterations: \"15\\r0\\u0001\"", &path);
  ExpectAt(error, path, 18, "solver.max_iterations");
  EXPECT_THAT(error.what(), HasSubstr("expected a whole number (e.g. 200), got '15\\r0\\x01'"));
  error = ErrorWith(dir, "  num_threads: 2", "  \"num\\tthreads\": 2", &path);
  EXPECT_THAT(error.what(), HasSubstr("unknown key 'num\\tthreads' in 'solver'"));
}

}  // namespace
}  // namespace dwellfit
