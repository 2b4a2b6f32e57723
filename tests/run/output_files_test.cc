#include "dwellfit/estimator/run/output_files.h"

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("output_files_" + name);
  fs::remove_all(dir);
  return dir;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The id of a process that has ended (a child that exited and was reaped).
pid_t EndedProcessId() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

std::vector<std::string> Entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(WriteFilesAtomically, WritesTheFilesThenAManifestListingThem) {
  const fs::path dir = FreshDir("manifest") / "nested" / "out";
  WriteFilesAtomically(dir.string(), {{"result.yaml", "a: 1\n"}, {"predictions.csv", "x\n1\n2\n"}});
  EXPECT_EQ(ReadFile(dir / "result.yaml"), "a: 1\n");
  EXPECT_EQ(ReadFile(dir / "predictions.csv"), "x\n1\n2\n");
  const YAML::Node manifest = YAML::LoadFile((dir / kManifestFileName).string());
  ASSERT_EQ(manifest["files"].size(), 2u);
  EXPECT_EQ(manifest["files"][0]["name"].as<std::string>(), "result.yaml");
  EXPECT_EQ(manifest["files"][0]["bytes"].as<int>(), 5);
  EXPECT_EQ(manifest["files"][1]["name"].as<std::string>(), "predictions.csv");
  EXPECT_EQ(manifest["files"][1]["bytes"].as<int>(), 6);
  EXPECT_FALSE(manifest["dwellfit_version"].as<std::string>().empty());
  // Nothing but the run's files, its manifest and the lock is left.
  EXPECT_EQ(Entries(dir), (std::vector<std::string>{".dwellfit-lock", "manifest.yaml",
                                                    "predictions.csv", "result.yaml"}));
}

TEST(WriteFilesAtomically, RemovesWhatAKilledRunLeftAndKeepsALiveRunsStaging) {
  const fs::path dir = FreshDir("stale");
  const pid_t ended = EndedProcessId();
  const pid_t alive = ::getppid();
  fs::create_directories(dir / (".dwellfit-staging-" + std::to_string(ended)));
  std::ofstream(dir / (".dwellfit-staging-" + std::to_string(ended)) / "result.yaml") << "half";
  std::ofstream(dir / ("result.yaml.partial-" + std::to_string(ended))) << "half";
  fs::create_directories(dir / (".dwellfit-staging-" + std::to_string(alive)));
  std::ofstream(dir / "notes.txt") << "the user's own file";

  WriteFilesAtomically(dir.string(), {{"result.yaml", "a: 2\n"}});
  EXPECT_EQ(Entries(dir), (std::vector<std::string>{".dwellfit-lock",
                                                    ".dwellfit-staging-" + std::to_string(alive),
                                                    "manifest.yaml", "notes.txt", "result.yaml"}));
  EXPECT_EQ(ReadFile(dir / "result.yaml"), "a: 2\n");
}

// A run that writes fewer files (no figures) removes the previous run's
// others, and only those: the user's own files and paths out of the
// directory a manifest might name stay.
TEST(WriteFilesAtomically, RemovesThePreviousRunsFilesItDoesNotWriteAgain) {
  const fs::path dir = FreshDir("fewer");
  std::ofstream(dir.parent_path() / "outside.txt") << "not the run's";
  WriteFilesAtomically(dir.string(), {{"result.yaml", "first\n"}, {"figure_fit_F1.png", "png"}});
  std::ofstream(dir / "notes.txt") << "the user's own file";
  std::ofstream(dir / kManifestFileName, std::ios::app)
      << "  - {name: ../outside.txt, bytes: 13}\n";
  WriteFilesAtomically(dir.string(), {{"result.yaml", "second\n"}});
  EXPECT_EQ(Entries(dir), (std::vector<std::string>{".dwellfit-lock", "manifest.yaml", "notes.txt",
                                                    "result.yaml"}));
  EXPECT_TRUE(fs::exists(dir.parent_path() / "outside.txt"));
}

TEST(WriteFilesAtomically, AFailedWriteKeepsThePreviousRunWhole) {
  const fs::path dir = FreshDir("failed");
  WriteFilesAtomically(dir.string(), {{"result.yaml", "first\n"}});
  const std::string manifest = ReadFile(dir / kManifestFileName);
  // A name in a folder that does not exist cannot be written.
  EXPECT_THROW(WriteFilesAtomically(
                   dir.string(), {{"result.yaml", "second\n"}, {"missing/predictions.csv", "x\n"}}),
               InputError);
  EXPECT_EQ(ReadFile(dir / "result.yaml"), "first\n");
  EXPECT_EQ(ReadFile(dir / kManifestFileName), manifest);
  EXPECT_EQ(Entries(dir),
            (std::vector<std::string>{".dwellfit-lock", "manifest.yaml", "result.yaml"}));
}

TEST(CheckOutputDirectory, AcceptsADirectoryThatDoesNotExistYetAndCreatesNothing) {
  const fs::path parent = FreshDir("check_new");
  fs::create_directories(parent);
  CheckOutputDirectory((parent / "a" / "b").string(), "output_dir");
  EXPECT_TRUE(Entries(parent).empty());
  CheckOutputDirectory(parent.string(), "output_dir");
}

TEST(CheckOutputDirectory, NamesAFileThatStandsWhereADirectoryMustBe) {
  const fs::path parent = FreshDir("check_file");
  fs::create_directories(parent);
  std::ofstream(parent / "blocked") << "not a directory";
  for (const fs::path& path : {parent / "blocked", parent / "blocked" / "out"}) {
    try {
      CheckOutputDirectory(path.string(), "--output_dir");
      FAIL() << path << " was accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.field(), "--output_dir");
      EXPECT_THAT(error.what(),
                  HasSubstr("'" + (parent / "blocked").string() + "' is not a directory"));
      EXPECT_THAT(error.what(), HasSubstr("choose another output_dir"));
    }
  }
}

}  // namespace
}  // namespace dwellfit
