// Fuzz bodies of the files the trace, rig, curves and study tools read: a
// trace set (index and samples) through processing, a rig file, an identify
// result.yaml, and a sensitivity shard through the merge. Inputs of two files
// are split at their first NUL byte: the text before it is the first file,
// the bytes after it the second.
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

#include "dwellfit/config/result_parameters.h"
#include "dwellfit/config/rig_config_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/studies/sensitivity_study.h"
#include "dwellfit/estimator/traces/trace_file.h"
#include "dwellfit/estimator/traces/trace_processing.h"
#include "tests/fuzz/fuzz_targets.h"
#include "tests/fuzz/scratch_dir.h"

namespace dwellfit::fuzz {
namespace {

std::pair<std::string, std::string> SplitAtNul(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string::size_type nul = input.find('\0');
  if (nul == std::string::npos) return {input, std::string()};
  return {input.substr(0, nul), input.substr(nul + 1)};
}

// A folder of ScratchDir() holding `first` and `second` as the two files.
std::string WriteFolder(const std::string& folder, const std::string& first_name,
                        const std::string& second_name, const std::uint8_t* data,
                        std::size_t size) {
  const auto [first, second] = SplitAtNul(data, size);
  std::filesystem::create_directories(ScratchDir() + "/" + folder);
  WriteScratchFile(folder + "/" + first_name, first);
  WriteScratchFile(folder + "/" + second_name, second);
  return ScratchDir() + "/" + folder;
}

void Require(bool holds, const std::string& what) {
  if (!holds) throw std::logic_error(what);
}

bool PositiveFinite(double value) { return value > 0.0 && std::isfinite(value); }

}  // namespace

void TraceSetBody(const std::uint8_t* data, std::size_t size) {
  const std::string folder =
      WriteFolder("traces", kTraceIndexFile, kTraceSamplesFile, data, size);
  ProcessedTraces processed;
  try {
    processed = ProcessTraces(ReadTraceSet(folder), TraceProcessingOptions());
  } catch (const InputError&) {
    return;
  }
  // An accepted set gives measurements: finite, positive amplitudes and
  // levels, and a finite lag, at every dwell.
  for (const Sweep& sweep : processed.sweeps) {
    for (const DwellPoint& point : sweep.points) {
      const std::string at = "ProcessTraces: sweep " + sweep.Name() + ": ";
      Require(PositiveFinite(point.amplitude), at + "amplitude not positive and finite");
      Require(PositiveFinite(point.a_base), at + "a_base not positive and finite");
      Require(point.phase_rad && std::isfinite(*point.phase_rad), at + "lag not finite");
    }
  }
}

void RigConfigBody(const std::uint8_t* data, std::size_t size) {
  RigConfig rig;
  try {
    rig = ParseRigConfig(std::string(reinterpret_cast<const char*>(data), size), "rig.yaml");
  } catch (const InputError&) {
    return;
  }
  std::string why;
  Require(rig.rig.IsValid(&why), "ParseRigConfig accepted invalid rig options: " + why);
  Require(rig.processing.IsValid(&why), "ParseRigConfig accepted invalid processing: " + why);
}

void ResultParametersBody(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteScratchFile("result.yaml", data, size);
  ParameterVector parameters{};
  try {
    parameters = ReadResultParameters(path);
  } catch (const InputError&) {
    return;
  }
  for (double value : parameters) Require(std::isfinite(value), "a parameter is not finite");
}

void ShardMergeBody(const std::uint8_t* data, std::size_t size) {
  const std::string folder = WriteFolder("shard", "study.yaml", "fits.csv", data, size);
  SensitivityStudy merged;
  try {
    merged = MergeShards({folder});
  } catch (const InputError&) {
    return;
  }
  // A merged study holds every fit of the study once, in order.
  Require(static_cast<int>(merged.rows.size()) == merged.total_fits,
          "MergeShards: the rows are not the study's fits");
  for (std::size_t i = 0; i < merged.rows.size(); ++i) {
    Require(merged.rows[i].fit == static_cast<int>(i), "MergeShards: fits out of order");
  }
}

}  // namespace dwellfit::fuzz
