#include "dwellfit/config/config_override.h"

#include <filesystem>
#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;
namespace fs = std::filesystem;

InputError SetFlagError(const std::string& flag_value) {
  return ErrorOf([&] { ParseSetFlag(flag_value, "--set"); });
}

InputError LoadErrorWith(const std::vector<ConfigOverride>& overrides) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(kValidConfig);
  return ErrorOf([&] { LoadIdentifyConfig(path, overrides); });
}

// Runs `body` with the working directory set to `directory`.
template <typename Body>
void InDirectory(const fs::path& directory, Body body) {
  const fs::path previous = fs::current_path();
  fs::current_path(directory);
  body();
  fs::current_path(previous);
}

TEST(ParseSetFlag, SplitsEntriesButNotInsideBracketsOrQuotes) {
  const std::vector<ConfigOverride> overrides = ParseSetFlag(
      "solver.max_iterations=50, fixed=[delta, omega],jump_detection={min_ratio: 3, "
      "min_relative_amplitude: 0.1},output_dir='a,b'",
      "--set");
  ASSERT_EQ(overrides.size(), 4u);
  EXPECT_EQ(overrides[0].key_path, "solver.max_iterations");
  EXPECT_EQ(overrides[0].yaml_value, "50");
  EXPECT_EQ(overrides[0].origin, "--set");
  EXPECT_EQ(overrides[0].action, OverrideAction::kReplace);
  EXPECT_EQ(overrides[1].key_path, "fixed");
  EXPECT_EQ(overrides[1].yaml_value, "[delta, omega]");
  EXPECT_EQ(overrides[2].key_path, "jump_detection");
  EXPECT_EQ(overrides[2].yaml_value, "{min_ratio: 3, min_relative_amplitude: 0.1}");
  EXPECT_EQ(overrides[3].yaml_value, "'a,b'");
}

TEST(ParseSetFlag, ANulCharacterIsAnError) {
  const InputError error = SetFlagError(std::string("output_dir='a\0b'", 16));
  EXPECT_THAT(error.what(), StartsWith("--set: the value holds a NUL character"));
}

TEST(ParseSetFlag, EmptyFlagGivesNoOverrides) { EXPECT_TRUE(ParseSetFlag("", "--set").empty()); }

TEST(ParseSetFlag, MalformedEntriesAreErrorsNamingTheFlag) {
  for (const std::string bad :
       {"solver.max_iterations", "=5", "solver..max_iterations=5", "fixed=[delta, omega",
        "fixed=delta]", "a=1,,b=2", "solver.max_iterations=", "output_dir='x"}) {
    const InputError error = SetFlagError(bad);
    EXPECT_THAT(error.what(), StartsWith("--set: ")) << bad;
  }
  EXPECT_THAT(SetFlagError("solver.max_iterations").what(), HasSubstr("has no '='"));
  EXPECT_THAT(SetFlagError("fixed=[delta, omega").what(), HasSubstr("missing ']'"));
  EXPECT_THAT(SetFlagError("effective_nonlinearity_reference_hz=").what(),
              HasSubstr("write effective_nonlinearity_reference_hz=null"));
}

TEST(ListFlagOverride, CommaListBecomesAYamlList) {
  const ConfigOverride fix = ListFlagOverride("fixed", "delta, omega", "--fix");
  EXPECT_EQ(fix.key_path, "fixed");
  EXPECT_EQ(fix.yaml_value, "[delta, omega]");
  EXPECT_EQ(fix.origin, "--fix");
  EXPECT_EQ(ListFlagOverride("fixed", "", "--fix").yaml_value, "[]");
  EXPECT_EQ(DescribeOverride(
                ListFlagOverride("fixed", "omega", "--free", OverrideAction::kRemoveFromList)),
            "--free fixed-=[omega]");
}

TEST(ConfigOverrides, ChangeTheValuesOfTheFile) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(kValidConfig);
  const std::vector<ConfigOverride> overrides = {
      {"solver.max_iterations", "50", "--set"},
      {"initial_guess.mu1", "0.3", "--set"},
      {"fixed", "[delta, omega]", "--fix"},
      {"stages", "[vertical]", "--stages"},
      {"residual.error", "absolute", "--residual_error"},
      {"output_dir", "/tmp/x", "--output_dir"},
      {"effective_nonlinearity_reference_hz", "null", "--set"},
  };
  const IdentifyConfig config = LoadIdentifyConfig(path, overrides);
  EXPECT_EQ(config.identification.solve.solver.max_iterations, 50);
  EXPECT_EQ(config.identification.solve.solver.num_threads, 2);  // the rest of the block stays
  EXPECT_EQ(config.identification.initial[kMu1], 0.3);
  EXPECT_EQ(config.identification.initial[kEtaE], 130.0);
  EXPECT_THAT(config.identification.fixed, ElementsAre(false, false, false, true, false, true));
  EXPECT_THAT(config.identification.solve.stages, ElementsAre(ResidualKind::kVertical));
  EXPECT_EQ(config.identification.solve.residual.error, ErrorMeasure::kAbsolute);
  EXPECT_EQ(config.output_dir, "/tmp/x");
  EXPECT_FALSE(config.omega_ref_rad_s.has_value());
  EXPECT_EQ(config.overrides.size(), overrides.size());
}

TEST(ConfigOverrides, CreateABlockTheFileLacks) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(Replace(
      kValidConfig, "jump_detection:\n  min_ratio: 3.0\n  min_relative_amplitude: 0.25\n", ""));
  const IdentifyConfig config =
      LoadIdentifyConfig(path, ParseSetFlag("jump_detection.min_ratio=4", "--set"));
  EXPECT_EQ(config.jump_detection.min_ratio, 4.0);
  EXPECT_EQ(config.jump_detection.min_relative_amplitude, 0.2);  // config/README.md's default
}

TEST(ConfigOverrides, FreeRemovesParametersFromFixed) {
  const ConfigDirectory dir;
  const std::string path =
      dir.WriteConfig(Replace(kValidConfig, "fixed: [omega]", "fixed: [delta, omega]"));
  const IdentifyConfig config = LoadIdentifyConfig(
      path, {ListFlagOverride("fixed", "omega", "--free", OverrideAction::kRemoveFromList)});
  EXPECT_THAT(config.identification.fixed, ElementsAre(false, false, false, true, false, false));
}

TEST(ConfigOverrides, RelativePathsAreRelativeToTheWorkingDirectory) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteFile("configs/identify.yaml", kValidConfig);
  dir.WriteFile("configs/sweeps.csv", "");
  dir.WriteFile("elsewhere/more.csv", "");
  IdentifyConfig config;
  InDirectory(dir.path() / "elsewhere", [&] {
    config = LoadIdentifyConfig(
        path, {{"output_dir", "results", "--output_dir"}, {"data", "[more.csv]", "--set"}});
  });
  EXPECT_EQ(config.output_dir, (dir.path() / "elsewhere" / "results").string());
  EXPECT_THAT(config.data_files, ElementsAre((dir.path() / "elsewhere" / "more.csv").string()));
}

TEST(ConfigOverrides, AppearInThePrintedConfig) {
  const ConfigDirectory dir;
  const std::string yaml = ConfigToYaml(LoadIdentifyConfig(
      dir.WriteConfig(kValidConfig), ParseSetFlag("solver.max_iterations=50", "--set")));
  EXPECT_THAT(yaml, HasSubstr("# override: --set solver.max_iterations=50"));
  EXPECT_THAT(yaml, HasSubstr("max_iterations: 50"));
}

TEST(ConfigOverrideErrors, UnknownKeyNamesTheFlagAndTheAllowedKeys) {
  const InputError error = LoadErrorWith(ParseSetFlag("solver.max_iteration=50", "--set"));
  EXPECT_EQ(error.file(), "--set");
  EXPECT_EQ(error.field(), "solver.max_iteration");
  EXPECT_THAT(error.what(), StartsWith("--set: field 'solver.max_iteration': unknown key "
                                       "'max_iteration' in 'solver'"));
  EXPECT_THAT(error.what(), HasSubstr("allowed: max_iterations, function_tolerance"));
}

TEST(ConfigOverrideErrors, UnknownTopLevelBlockNamesTheFlag) {
  const InputError error = LoadErrorWith(ParseSetFlag("solvr.max_iterations=50", "--set"));
  EXPECT_THAT(error.what(), StartsWith("--set: field 'solvr': unknown key 'solvr' at the top "
                                       "level (did you mean 'solver'?)"));
}

TEST(ConfigOverrideErrors, WrongTypeNamesTheFlag) {
  InputError error = LoadErrorWith(ParseSetFlag("solver.max_iterations=2.5", "--set"));
  EXPECT_THAT(error.what(), StartsWith("--set: field 'solver.max_iterations': expected a whole "
                                       "number (e.g. 200), got '2.5'"));
  error = LoadErrorWith({ListFlagOverride("fixed", "delta,omgea", "--fix")});
  EXPECT_THAT(error.what(), StartsWith("--fix: field 'fixed': unknown parameter 'omgea' (did "
                                       "you mean 'omega'?)"));
}

TEST(ConfigOverrideErrors, RemovingARequiredKeyNamesTheFlag) {
  const InputError error = LoadErrorWith(ParseSetFlag("output_dir=~", "--set"));
  EXPECT_THAT(error.what(), HasSubstr("--set"));
  EXPECT_THAT(error.what(), HasSubstr("output_dir"));
}

// A removal would otherwise pass unnoticed when its key is misspelt.
TEST(ConfigOverrideErrors, RemovingAKeyTheConfigDoesNotSetNamesTheFlag) {
  InputError error =
      LoadErrorWith(ParseSetFlag("effective_nonlinearity_reference_hx=null", "--set"));
  EXPECT_THAT(error.what(), StartsWith("--set: field 'effective_nonlinearity_reference_hx': "
                                       "nothing to remove: the config does not set"));
  error = LoadErrorWith(ParseSetFlag("solver.max_iteration=~", "--set"));
  EXPECT_THAT(error.what(), StartsWith("--set: field 'solver.max_iteration': nothing to remove"));
}

TEST(ConfigOverrideErrors, InvalidValueInAFileBlockNamesTheFlag) {
  const InputError error = LoadErrorWith({{"solver.max_iterations", "0", "--max_iterations"}});
  EXPECT_THAT(error.what(), HasSubstr(":17: field 'solver': solver.max_iterations must be at "
                                      "least 1 (values set on the command line: "
                                      "--max_iterations solver.max_iterations=0)"));
}

TEST(ConfigOverrideErrors, ValuesThatCannotBeAppliedNameTheFlag) {
  InputError error = LoadErrorWith(ParseSetFlag("data.file=x.csv", "--set"));
  EXPECT_THAT(error.what(), StartsWith("--set: field 'data.file': 'data' holds a single value, "
                                       "not a block of keys"));
  error = LoadErrorWith({{"fixed", "[delta", "--fix"}});
  EXPECT_THAT(error.what(), StartsWith("--fix: field 'fixed': value '[delta' is not valid YAML"));
  error = LoadErrorWith(
      {ListFlagOverride("fixed", "delta", "--free", OverrideAction::kRemoveFromList)});
  EXPECT_THAT(error.what(), StartsWith("--free: field 'fixed': cannot remove 'delta': it is not "
                                       "in 'fixed' ([omega])"));
}

TEST(ConfigOverrideErrors, FileErrorsStillNameTheFileLine) {
  // An override elsewhere does not take over the errors of values it did not set.
  const ConfigDirectory dir;
  const std::string path =
      dir.WriteConfig(Replace(kValidConfig, "  num_threads: 2", "  num_threads: two"));
  const InputError error =
      ErrorOf([&] { LoadIdentifyConfig(path, ParseSetFlag("solver.max_iterations=50", "--set")); });
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), 22);
  EXPECT_EQ(error.field(), "solver.num_threads");
}

// Hostile overrides (the override rows of the Hardening issue's table).

TEST(ParseSetFlag, ARepeatedKeyIsAnError) {
  // Before: the last value won.
  const InputError error = SetFlagError("k=5,solver.max_iterations=50,k=6");
  EXPECT_STREQ(error.what(),
               "--set: field 'k': 'k' is set twice (k=5 and k=6); give each key once");
}

TEST(ConfigOverrideErrors, TwoOverridesOfOneKeyConflict) {
  InputError error = LoadErrorWith({{"solver.max_iterations", "5", "--max_iterations"},
                                    {"solver.max_iterations", "6", "--set"}});
  EXPECT_STREQ(error.what(),
               "--set: field 'solver.max_iterations': conflicts with --max_iterations "
               "solver.max_iterations=5: both change it; give each key once");
  // A block and a key inside it conflict too.
  error = LoadErrorWith({{"solver", "{num_threads: 1}", "--set"},
                         {"solver.max_iterations", "6", "--max_iterations"}});
  EXPECT_THAT(error.what(), StartsWith("--max_iterations: field 'solver.max_iterations': "
                                       "conflicts with --set solver={num_threads: 1}"));
  // --set fixed=[...] would silently undo --fix.
  error = LoadErrorWith({ListFlagOverride("fixed", "delta", "--fix", OverrideAction::kAddToList),
                         {"fixed", "[mu1]", "--set"}});
  EXPECT_THAT(error.what(),
              StartsWith("--set: field 'fixed': conflicts with --fix fixed+=[delta]"));
}

TEST(ConfigOverrides, FixAddsToTheFixedListOfTheFile) {
  // Before: --fix replaced the list and so freed omega.
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(kValidConfig);  // fixed: [omega]
  IdentifyConfig config = LoadIdentifyConfig(
      path, {ListFlagOverride("fixed", "delta,omega", "--fix", OverrideAction::kAddToList)});
  EXPECT_THAT(config.identification.fixed, ElementsAre(false, false, false, true, false, true));
  EXPECT_THAT(ConfigToYaml(config), HasSubstr("# override: --fix fixed+=[delta, omega]"));
  // Added to a list the file lacks; --fix and --free of different names combine.
  const std::string without =
      dir.WriteFile("without.yaml", Replace(kValidConfig, "fixed: [omega]\n", ""));
  config = LoadIdentifyConfig(
      without, {ListFlagOverride("fixed", "mu2", "--fix", OverrideAction::kAddToList)});
  EXPECT_THAT(config.identification.fixed, ElementsAre(false, false, true, false, false, false));
  config = LoadIdentifyConfig(
      path, {ListFlagOverride("fixed", "mu2", "--fix", OverrideAction::kAddToList),
             ListFlagOverride("fixed", "omega", "--free", OverrideAction::kRemoveFromList)});
  EXPECT_THAT(config.identification.fixed, ElementsAre(false, false, true, false, false, false));
}

TEST(ConfigOverrideErrors, FixAndFreeOfOneNameConflict) {
  const InputError error = LoadErrorWith(
      {ListFlagOverride("fixed", "delta", "--fix", OverrideAction::kAddToList),
       ListFlagOverride("fixed", "mu1,delta", "--free", OverrideAction::kRemoveFromList)});
  EXPECT_STREQ(error.what(),
               "--free: field 'fixed': 'delta' is given to both --fix and --free; give it to one "
               "of them");
}

TEST(ConfigOverrideErrors, ErrorsAboutAnAddedEntryNameTheFlagAndAboutTheFileItsLine) {
  InputError error =
      LoadErrorWith({ListFlagOverride("fixed", "omgea", "--fix", OverrideAction::kAddToList)});
  EXPECT_THAT(error.what(), StartsWith("--fix: field 'fixed': unknown parameter 'omgea' (did "
                                       "you mean 'omega'?)"));
  const ConfigDirectory dir;
  const std::string path =
      dir.WriteConfig(Replace(kValidConfig, "fixed: [omega]", "fixed: [omega, mu3]"));
  error = ErrorOf([&] {
    LoadIdentifyConfig(path,
                       {ListFlagOverride("fixed", "delta", "--fix", OverrideAction::kAddToList)});
  });
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), 12);
  EXPECT_THAT(error.what(), HasSubstr("unknown parameter 'mu3'"));
  // A parameter --fix adds needs an initial guess too.
  const std::string no_delta =
      dir.WriteFile("no_delta.yaml", Replace(kValidConfig, "  delta: 1.3e4\n", ""));
  error = ErrorOf([&] {
    LoadIdentifyConfig(no_delta,
                       {ListFlagOverride("fixed", "delta", "--fix", OverrideAction::kAddToList)});
  });
  EXPECT_STREQ(error.what(),
               "--fix: field 'fixed': parameter 'delta' is fixed but has no initial guess, and a "
               "fixed parameter is held at the value the config gives: add initial_guess.delta "
               "(on the command line: --set initial_guess.delta=VALUE), or do not fix 'delta'");
}

TEST(ConfigOverrideErrors, AnEmptyFlagValueSaysSo) {
  // Before: --output_dir= removed the key and said "missing required key".
  InputError error = LoadErrorWith({{"output_dir", "", "--output_dir"}});
  EXPECT_STREQ(error.what(),
               "--output_dir: field 'output_dir': the flag's value is empty; give a value for "
               "'output_dir'");
  error = LoadErrorWith({ListFlagOverride("fixed", "", "--fix", OverrideAction::kAddToList)});
  EXPECT_STREQ(error.what(),
               "--fix: field 'fixed': the flag's value is empty; give the names to add to "
               "'fixed'");
  error =
      LoadErrorWith({ListFlagOverride("fixed", " , ", "--free", OverrideAction::kRemoveFromList)});
  EXPECT_THAT(error.what(), HasSubstr("give the names to remove from 'fixed'"));
}

// Two penalty blocks sharing one YAML anchor.
constexpr char kAliasedPenalties[] = R"(penalties:
  bifurcation_range: &common {enabled: true, weight: 2}
  branch_stability: *common
)";

TEST(ConfigOverrides, SetOnAnAliasedBlockChangesOnlyTheNamedPath) {
  // Before: the alias was written through, changing both blocks.
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(
      Replace(kValidConfig, "output_dir:", std::string(kAliasedPenalties) + "output_dir:"));
  IdentifyConfig config = LoadIdentifyConfig(path);
  EXPECT_EQ(config.identification.solve.penalties.branch_stability.weight, 2.0);  // the alias reads
  config = LoadIdentifyConfig(path, ParseSetFlag("penalties.branch_stability.weight=5", "--set"));
  EXPECT_EQ(config.identification.solve.penalties.branch_stability.weight, 5.0);
  EXPECT_EQ(config.identification.solve.penalties.bifurcation_range.weight, 2.0);
  EXPECT_TRUE(config.identification.solve.penalties.branch_stability.enabled);
  config = LoadIdentifyConfig(path,
                              ParseSetFlag("penalties.branch_stability={enabled: false}", "--set"));
  EXPECT_FALSE(config.identification.solve.penalties.branch_stability.enabled);
  EXPECT_TRUE(config.identification.solve.penalties.bifurcation_range.enabled);
  // A value the override did not set still names its line in the file.
  const std::string bad = dir.WriteFile(
      "bad.yaml",
      Replace(Replace(kValidConfig, "output_dir:", std::string(kAliasedPenalties) + "output_dir:"),
              "enabled: true", "enabled: maybe"));
  const InputError error = ErrorOf([&] {
    LoadIdentifyConfig(bad, ParseSetFlag("penalties.branch_stability.weight=5", "--set"));
  });
  EXPECT_EQ(error.file(), bad);
  EXPECT_EQ(error.line(), 28);
  EXPECT_THAT(error.what(), HasSubstr("expected true or false, got 'maybe'"));
}

// `initial_guess: auto` is the block with every key auto: --set of one key
// gives that key, the others stay auto. Before: "'initial_guess' holds a
// single value".
TEST(ConfigOverrides, SetOfOneGuessOnAnAutoInitialGuess) {
  const ConfigDirectory dir;
  const std::string text = Replace(kValidConfig, "fixed: [omega]\n", "fixed: []\n");
  const std::string::size_type begin = text.find("initial_guess:");
  const std::string::size_type end = text.find("fixed:");
  ASSERT_NE(begin, std::string::npos);
  ASSERT_LT(begin, end);
  const std::string auto_path = dir.WriteFile(
      "auto.yaml", text.substr(0, begin) + "initial_guess: auto\n" + text.substr(end));
  const IdentifyConfig config =
      LoadIdentifyConfig(auto_path, ParseSetFlag("initial_guess.delta=0", "--set"));
  EXPECT_TRUE(config.initial_guess[kDelta].has_value());
  EXPECT_EQ(*config.initial_guess[kDelta], 0.0);
  for (ParameterIndex index : {kEtaE, kMu1, kMu2, kAlpha, kNaturalFrequency}) {
    EXPECT_FALSE(config.initial_guess[index].has_value()) << ParameterName(index);
  }
  // Two keys at once, omega in Hz.
  const IdentifyConfig two = LoadIdentifyConfig(
      auto_path, ParseSetFlag("initial_guess.delta=5,initial_guess.omega_hz=41", "--set"));
  EXPECT_EQ(*two.initial_guess[kDelta], 5.0);
  EXPECT_DOUBLE_EQ(*two.initial_guess[kNaturalFrequency], HzToRadPerSecond(41.0));
}

// --fix of a parameter the config leaves to the data takes its value from
// --set initial_guess.X=V (what select_model's recommendation needs, e.g.
// `--fix delta,mu2 --set initial_guess.delta=0,initial_guess.mu2=0`).
TEST(ConfigOverrides, FixTakesItsValueFromSetOnAnAutoInitialGuess) {
  const ConfigDirectory dir;
  const std::string text = Replace(kValidConfig, "fixed: [omega]\n", "fixed: []\n");
  const std::string::size_type begin = text.find("initial_guess:");
  const std::string::size_type end = text.find("fixed:");
  const std::string path = dir.WriteFile(
      "auto.yaml", text.substr(0, begin) + "initial_guess: auto\n" + text.substr(end));
  std::vector<ConfigOverride> overrides =
      ParseSetFlag("initial_guess.delta=0,initial_guess.mu2=0", "--set");
  overrides.push_back(ListFlagOverride("fixed", "delta,mu2", "--fix", OverrideAction::kAddToList));
  const IdentifyConfig config = LoadIdentifyConfig(path, overrides);
  EXPECT_THAT(config.identification.fixed, ElementsAre(false, false, true, true, false, false));
  EXPECT_EQ(config.identification.initial[kDelta], 0.0);
  EXPECT_EQ(config.identification.initial[kMu2], 0.0);
  // Without the --set, the error says how to give the value.
  const InputError error = ErrorOf([&] {
    LoadIdentifyConfig(path,
                       {ListFlagOverride("fixed", "delta", "--fix", OverrideAction::kAddToList)});
  });
  EXPECT_THAT(error.what(), HasSubstr("--set initial_guess.delta=VALUE"));
}

TEST(ConfigOverrides, SetOnAnAliasedValueChangesOnlyThatKey) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(Replace(
      Replace(kValidConfig, "  omega_hz: 40", "  omega_hz: &f 41"),
      "effective_nonlinearity_reference_hz: 41", "effective_nonlinearity_reference_hz: *f"));
  const IdentifyConfig config =
      LoadIdentifyConfig(path, ParseSetFlag("initial_guess.omega_hz=40", "--set"));
  EXPECT_DOUBLE_EQ(config.identification.initial[kNaturalFrequency], HzToRadPerSecond(40.0));
  EXPECT_DOUBLE_EQ(*config.omega_ref_rad_s, HzToRadPerSecond(41.0));
}

}  // namespace
}  // namespace dwellfit
