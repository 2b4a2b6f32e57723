// Turns the time traces of a sine-dwell test into the sweeps CSV identify
// reads (with the phase), and optionally identifies the parameters by
// harmonic balance (estimator/traces/harmonic_balance.h).
//
//   process_traces --rig datasets/virtual-beam/rig.yaml \
//                  --traces datasets/virtual-beam/traces \
//                  --out datasets/virtual-beam/sweeps.csv \
//                  [--harmonic_balance=hb.yaml [--reference_hz=41.5]]
//
// or, from UFF data set 58 time histories (estimator/traces/uff58_traces.h),
// --uff datasets/virtual-beam/traces-uff/virtual-beam-58b.csv in place of
// --traces.
//
// Warnings (unsettled dwells, strong harmonics, base levels off the sweep's
// mean) are printed. With an unsettled dwell nothing is written and the exit
// code is 3, unless --allow_unsettled; bad input exits 1.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/config/rig_config_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/estimator/traces/harmonic_balance.h"
#include "dwellfit/estimator/traces/trace_processing.h"
#include "dwellfit/estimator/traces/uff58_traces.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(rig, "", "YAML rig: channels, beam and gauge, processing (required).");
DEFINE_string(traces, "", "Folder holding traces.csv and traces.f32 (or give --uff).");
DEFINE_string(uff, "", "UFF index CSV naming each dwell's data sets 58 (instead of --traces).");
DEFINE_string(out, "",
              "Sweeps CSV to write (sweep,direction,freq_hz,a_base,a,phase_rad,a_base_sigma).");
DEFINE_string(harmonic_balance, "", "If set, also identify by harmonic balance into this YAML.");
DEFINE_double(reference_hz, 0.0, "Omega_ref [Hz] of the effective nonlinearity (0: identified w).");
DEFINE_bool(allow_unsettled, false, "Write the results even when a dwell looks unsettled.");

namespace {

// Stages `text` as `path`.partial, listed in `staged` (removed again when the
// run fails); Commit renames it into place.
std::string Stage(const std::string& text, const std::string& path,
                  std::vector<std::string>* staged) {
  // The process id keeps two runs into one --out from sharing a staged file.
  const std::string name = path + ".partial." + std::to_string(::getpid());
  staged->push_back(name);
  std::ofstream file(name, std::ios::binary | std::ios::trunc);
  file << text;
  file.close();
  if (!file) throw dwellfit::InputError(path, 0, "", "cannot write the file; check its folder");
  return name;
}

void Commit(const std::string& staged, const std::string& path) {
  if (std::rename(staged.c_str(), path.c_str()) != 0) {
    throw dwellfit::InputError(path, 0, "", "cannot rename the written file into place");
  }
}

// Throws InputError, before anything is read or written, when an output
// flag names a folder or an input, or both outputs name one file; or when
// --reference_hz is negative or not finite.
void CheckFlags() {
  if (!(FLAGS_reference_hz >= 0.0 && std::isfinite(FLAGS_reference_hz))) {
    throw dwellfit::InputError("--reference_hz", 0, "",
                               "give a frequency >= 0 in Hz (0: the identified omega)");
  }
  const std::filesystem::path traces(FLAGS_traces);
  std::vector<std::string> inputs = {FLAGS_rig, FLAGS_uff};
  if (!FLAGS_traces.empty()) {
    inputs.push_back((traces / "traces.csv").string());
    inputs.push_back((traces / "traces.f32").string());
  }
  dwellfit::CheckOutputFile(FLAGS_out, "--out", inputs);
  if (FLAGS_harmonic_balance.empty()) return;
  dwellfit::CheckOutputFile(FLAGS_harmonic_balance, "--harmonic_balance", inputs);
  if (dwellfit::SameFile(FLAGS_out, FLAGS_harmonic_balance)) {
    throw dwellfit::InputError(FLAGS_out, 0, "--harmonic_balance",
                               "names the same file as --out; give two files");
  }
}

// Reads, processes and writes (see the top of this file); returns the exit
// status. What it stages is listed in `staged`.
int ProcessAndWrite(std::vector<std::string>* staged) {
  CheckFlags();
  const dwellfit::RigConfig rig = dwellfit::ReadRigConfig(FLAGS_rig);
  const auto dwells = FLAGS_uff.empty() ? dwellfit::ReadTraceSet(FLAGS_traces)
                                        : dwellfit::ReadUffTraceSet(FLAGS_uff);
  const dwellfit::ProcessedTraces processed = dwellfit::ProcessTraces(dwells, rig.processing);
  for (const std::string& warning : processed.warnings) {
    std::cerr << "warning: " << warning << "\n";
  }
  if (processed.unsettled_dwells > 0 && !FLAGS_allow_unsettled) {
    std::cerr << "process_traces: " << processed.unsettled_dwells
              << " dwell(s) look unsettled; nothing written (record them again after a longer "
                 "wait, or pass --allow_unsettled)\n";
    return 3;
  }
  std::string hb_text;
  if (!FLAGS_harmonic_balance.empty()) {
    const dwellfit::HarmonicBalanceResult result =
        dwellfit::IdentifyHarmonicBalance(processed.harmonics, rig.processing.harmonics,
                                          dwellfit::HzToRadPerSecond(FLAGS_reference_hz));
    std::ostringstream yaml;
    dwellfit::WriteHarmonicBalanceYaml(result, &yaml);
    hb_text = yaml.str();
  }
  // Both files are written in full before either is renamed into place.
  std::ostringstream csv;
  dwellfit::WriteSweepsCsv(processed.sweeps, &csv);
  const std::string staged_csv = Stage(csv.str(), FLAGS_out, staged);
  const std::string staged_hb =
      hb_text.empty() ? std::string() : Stage(hb_text, FLAGS_harmonic_balance, staged);
  Commit(staged_csv, FLAGS_out);
  if (!staged_hb.empty()) Commit(staged_hb, FLAGS_harmonic_balance);
  std::cout << "processed " << dwells.size() << " dwells; wrote " << FLAGS_out << "\n";
  if (!hb_text.empty()) std::cout << hb_text << "wrote " << FLAGS_harmonic_balance << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "process_traces",
      "Dwell points (and optionally harmonic-balance estimates) from sine-dwell time traces.\n"
      "Usage: process_traces --rig rig.yaml (--traces folder | --uff index.csv) --out sweeps.csv",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_rig.empty() || FLAGS_traces.empty() == FLAGS_uff.empty() || FLAGS_out.empty()) {
      std::cerr << "process_traces: give --rig, --out and one of --traces or --uff; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    std::vector<std::string> staged;
    try {
      return ProcessAndWrite(&staged);
    } catch (...) {
      for (const std::string& name : staged) std::remove(name.c_str());
      throw;
    }
  });
}
