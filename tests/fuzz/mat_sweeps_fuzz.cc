// Fuzz body of the sweeps MAT file loader (estimator/matfile/mat_sweeps.h):
// the input is written to a .mat file and loaded. A v7.3 input is read by
// HDF5 in a child process (estimator/matfile/child_process.h): what HDF5 does
// there becomes a refusal of the file, and the loader goes on. An accepted file must give
// sweeps that hold what the loader documents (those of the CSV loader).
#include <matio.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/matfile/mat_sweeps.h"
#include "tests/fuzz/fuzz_targets.h"
#include "tests/fuzz/scratch_dir.h"

namespace dwellfit::fuzz {
namespace {

bool PositiveFinite(double value) { return value > 0.0 && std::isfinite(value); }

void Require(bool holds, const Sweep& sweep, const std::string& what) {
  if (!holds) throw std::logic_error("LoadSweepsMat: sweep " + sweep.Name() + ": " + what);
}

// libmatio's messages about damaged files, which would flood the output.
void Discard(int /*level*/, char* /*message*/) {}

}  // namespace

void MatSweepsBody(const std::uint8_t* data, std::size_t size) {
  static const int quiet = Mat_LogInitFunc("fuzz_mat_sweeps", &Discard);
  (void)quiet;
  const std::string path = WriteScratchFile("sweeps.mat", data, size);
  LoadedSweeps loaded;
  try {
    loaded = LoadSweepsMat(path);
  } catch (const InputError&) {
    return;
  }
  for (const Sweep& sweep : loaded.sweeps) {
    Require(!sweep.id.empty() && !sweep.points.empty(), sweep, "empty id or no dwells");
    Require(sweep.dropped_nonpositive == static_cast<int>(sweep.missing.size()), sweep,
            "dropped_nonpositive differs from the missing rows listed");
    for (const DwellPoint& point : sweep.points) {
      const std::string at = "row " + std::to_string(point.source_line) + ": ";
      Require(PositiveFinite(point.drive_frequency_rad_s) && PositiveFinite(point.a_base) &&
                  PositiveFinite(point.amplitude),
              sweep, at + "a control or the amplitude");
      Require(!point.phase_rad || std::isfinite(*point.phase_rad), sweep, at + "phase");
      Require(!point.sigma || PositiveFinite(*point.sigma), sweep, at + "sigma");
      Require(!point.a_base_sigma || PositiveFinite(*point.a_base_sigma), sweep,
              at + "a_base_sigma");
      Require(sweep.kind != SweepKind::kFrequency ||
                  point.a_base_sigma == sweep.points.front().a_base_sigma,
              sweep, at + "a frequency sweep's a_base_sigma differs from its first dwell's");
      Require(point.source_line >= 1, sweep, at + "row before the first");
    }
  }
}

}  // namespace dwellfit::fuzz
