// Writes a trace set (estimator/traces/trace_file.h) as UFF data set 58 time
// histories with the index process_traces --uff reads
// (estimator/traces/uff58_traces.h): the virtual beam's UFF rendition.
//
//   traces_to_uff --traces datasets/virtual-beam/traces \
//                 --out datasets/virtual-beam/traces-uff/virtual-beam-58b.uff \
//                 --index datasets/virtual-beam/traces-uff/virtual-beam-58b.csv \
//                 [--ascii] [--dwells=4] [--base_unit=g]
//
// Binary 58b in single precision by default (the samples exactly); --ascii
// writes ASCII 58 in double precision (E20.12, again exact). --dwells keeps
// the first N dwells (0: all). The index names the UFF file by its name, so
// both go into one folder. Bad input exits 1.
#include <filesystem>
#include <iostream>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/traces/uff58_traces.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"

DEFINE_string(traces, "", "Folder holding traces.csv and traces.f32 (required).");
DEFINE_string(out, "", "UFF file to write (required).");
DEFINE_string(index, "", "UFF index CSV to write, in the folder of --out (required).");
DEFINE_bool(ascii, false, "Write ASCII data set 58 (double precision) instead of binary 58b.");
DEFINE_int32(dwells, 0, "Write only the first N dwells (0: all).");
DEFINE_string(base_unit, "g", "Unit of the base channel (the data's a_base unit).");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "traces_to_uff",
      "Writes a trace set as UFF data set 58 time histories and their index.\n"
      "Usage: traces_to_uff --traces folder --out file.uff --index file.csv [--ascii]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_traces.empty() || FLAGS_out.empty() || FLAGS_index.empty()) {
      std::cerr << "traces_to_uff: give --traces, --out and --index; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    namespace fs = std::filesystem;
    if (fs::absolute(FLAGS_out).parent_path() != fs::absolute(FLAGS_index).parent_path()) {
      throw dwellfit::InputError(FLAGS_index, 0, "--index",
                                 "give a file in the folder of --out (the index names it)");
    }
    if (FLAGS_dwells < 0) throw dwellfit::InputError("--dwells: give a count >= 0");
    auto dwells = dwellfit::ReadTraceSet(FLAGS_traces);
    if (FLAGS_dwells > 0 && static_cast<std::size_t>(FLAGS_dwells) < dwells.size()) {
      dwells.resize(static_cast<std::size_t>(FLAGS_dwells));
    }
    dwellfit::WriteUffTraceSet(dwells, FLAGS_out, FLAGS_index, !FLAGS_ascii, FLAGS_base_unit);
    std::cout << "wrote " << dwells.size() << " dwells to " << FLAGS_out << " and " << FLAGS_index
              << "\n";
    return 0;
  });
}
