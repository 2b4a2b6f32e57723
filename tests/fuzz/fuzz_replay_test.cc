// Replays the fuzz targets' committed inputs through their bodies
// (fuzz_targets.h) in the regular test suite: the regression inputs of
// tests/fuzz/regressions/<target>/ (each once a finding), the seeds of
// tests/fuzz/corpus/<target>/ and the datasets' files. A body that crashes,
// reports under the sanitizers or throws anything but InputError fails.
#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "tests/fuzz/fuzz_targets.h"

namespace dwellfit::fuzz {

// Test names show the target's name.
void PrintTo(const FuzzTarget& target, std::ostream* os) { *os << target.name; }

namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = DWELLFIT_SOURCE_DIR;

// The regular files directly in `directory` (none when it does not exist),
// sorted; with a non-empty `extension`, only those ending in it.
std::vector<fs::path> FilesIn(const fs::path& directory, const std::string& extension = "") {
  std::vector<fs::path> files;
  if (!fs::is_directory(directory)) return files;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory)) {
    if (!entry.is_regular_file()) continue;
    if (!extension.empty() && entry.path().extension() != extension) continue;
    if (entry.path().filename().string().front() == '.') continue;  // .gitkeep
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Every input of `target`: regressions, seeds, then the datasets' files.
std::vector<fs::path> InputsOf(const FuzzTarget& target) {
  std::vector<fs::path> inputs = FilesIn(kSourceDir / "tests/fuzz/regressions" / target.name);
  for (const fs::path& seed : FilesIn(kSourceDir / "tests/fuzz/corpus" / target.name)) {
    inputs.push_back(seed);
  }
  if (target.dataset_extension.empty()) return inputs;
  std::vector<fs::path> dataset_dirs;
  for (const fs::directory_entry& entry : fs::directory_iterator(kSourceDir / "datasets")) {
    if (entry.is_directory()) dataset_dirs.push_back(entry.path());
  }
  std::sort(dataset_dirs.begin(), dataset_dirs.end());
  for (const fs::path& dir : dataset_dirs) {
    for (const fs::path& file : FilesIn(dir, target.dataset_extension)) inputs.push_back(file);
  }
  return inputs;
}

std::string ReadAll(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

class FuzzReplayTest : public testing::TestWithParam<FuzzTarget> {};

TEST_P(FuzzReplayTest, EveryCommittedInputIsAcceptedOrRejectedWithInputError) {
  QuietLogging();
  const FuzzTarget& target = GetParam();
  const std::vector<fs::path> inputs = InputsOf(target);
  ASSERT_FALSE(FilesIn(kSourceDir / "tests/fuzz/corpus" / target.name).empty())
      << "no seeds in tests/fuzz/corpus/" << target.name;
  for (const fs::path& input : inputs) {
    SCOPED_TRACE(input.string());
    const std::string bytes = ReadAll(input);
    try {
      target.body(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    } catch (const std::exception& e) {
      ADD_FAILURE() << "finding: " << e.what();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllTargets, FuzzReplayTest, testing::ValuesIn(AllFuzzTargets()),
                         [](const testing::TestParamInfo<FuzzTarget>& info) {
                           return info.param.name;
                         });

}  // namespace
}  // namespace dwellfit::fuzz
