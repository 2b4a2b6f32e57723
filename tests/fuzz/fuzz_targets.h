// The fuzz targets' bodies, as plain functions: the libFuzzer executables
// (libfuzzer_entry.cc) call them for generated inputs, and the regular test
// suite (fuzz_replay_test.cc) replays the committed seeds and regression
// inputs through them in any build.
//
// A body returns normally when the loader accepts its input or rejects it
// with dwellfit::InputError, the expected rejection of bad input. Anything
// else is a finding: a crash, a sanitizer report, a hang, or an exception of
// another type escaping (including the std::logic_error a body throws when an
// accepted input breaks a documented property of the result).
#ifndef DWELLFIT_TESTS_FUZZ_FUZZ_TARGETS_H_
#define DWELLFIT_TESTS_FUZZ_FUZZ_TARGETS_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dwellfit::fuzz {

using FuzzBody = void (*)(const std::uint8_t* data, std::size_t size);

// The input as the text of a sweeps CSV file (LoadSweepsCsv).
void SweepCsvBody(const std::uint8_t* data, std::size_t size);
// The input as an identify config file (LoadIdentifyConfig), beside an
// (empty) `sweeps.csv`; an accepted config must print (ConfigToYaml) as text
// that reads back to the same config.
void IdentifyConfigBody(const std::uint8_t* data, std::size_t size);
// The input as the value of `--set` (ParseSetFlag), applied to a complete
// config; the result must print and read back like IdentifyConfigBody's.
void SetFlagBody(const std::uint8_t* data, std::size_t size);
// The input as a dwell plan (ParseDwellPlan); every accepted sweep must give
// its control grid.
void DwellPlanBody(const std::uint8_t* data, std::size_t size);

// The input as a trace set: the index (traces.csv) before the first NUL
// byte, the samples (traces.f32) after it; an accepted set is processed, and
// every dwell must give a positive, finite amplitude and level and a lag.
void TraceSetBody(const std::uint8_t* data, std::size_t size);
// The input as a rig file (ParseRigConfig); accepted options must be valid.
void RigConfigBody(const std::uint8_t* data, std::size_t size);
// The input as an identify result.yaml (ReadResultParameters, as `curves
// --result` reads it); accepted parameters must be finite.
void ResultParametersBody(const std::uint8_t* data, std::size_t size);
// The input as one sensitivity shard folder: study.yaml before the first NUL
// byte, fits.csv after it (MergeShards); a merged study holds each of its
// fits once, in order.
void ShardMergeBody(const std::uint8_t* data, std::size_t size);
// The input as a UFF file (ParseUff58); every data set 58 read holds the
// values its header announces, all finite, and reads back the same after
// AppendUff58.
void Uff58Body(const std::uint8_t* data, std::size_t size);

// The input as a sweeps MAT file (LoadSweepsMat); accepted sweeps hold
// positive, finite dwells, as LoadSweepsCsv's.
void MatSweepsBody(const std::uint8_t* data, std::size_t size);

struct FuzzTarget {
  std::string name;  // tests/fuzz/corpus/<name>, tests/fuzz/regressions/<name>
  FuzzBody body;
  // Files under datasets/ that are seeds of this target ("" for none).
  std::string dataset_extension;
};

// Every target, in a fixed order.
const std::vector<FuzzTarget>& AllFuzzTargets();

// Makes logging quiet (errors only): the loaders LOG(WARNING) about dropped
// rows, which would cost more than the loading itself.
void QuietLogging();

}  // namespace dwellfit::fuzz

#endif  // DWELLFIT_TESTS_FUZZ_FUZZ_TARGETS_H_
