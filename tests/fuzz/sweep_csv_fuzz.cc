// Fuzz body of the sweeps CSV loader (estimator/sweep_csv.h): the input is
// written to a file and loaded, then jump detection runs on the sweeps, as
// identify does. An accepted file must give sweeps that hold what the loader
// documents.
#include <cmath>
#include <stdexcept>
#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "tests/fuzz/fuzz_targets.h"
#include "tests/fuzz/scratch_dir.h"

namespace dwellfit::fuzz {
namespace {

bool PositiveFinite(double value) { return value > 0.0 && std::isfinite(value); }

void Require(bool holds, const Sweep& sweep, const std::string& what) {
  if (!holds) throw std::logic_error("LoadSweepsCsv: sweep " + sweep.Name() + ": " + what);
}

// What sweep_csv.h promises of an accepted file: every sweep kept has dwells,
// whose controls and amplitudes are positive and finite (in rad/s for the
// frequency), optional values finite (standard deviations positive, one
// a_base_sigma per frequency sweep), and lines after the header.
void CheckLoadedSweeps(const LoadedSweeps& loaded) {
  int missing_rows = 0;
  for (const Sweep& sweep : loaded.sweeps) {
    Require(!sweep.id.empty(), sweep, "empty id");
    Require(!sweep.points.empty(), sweep, "kept without dwells");
    Require(sweep.dropped_nonpositive == static_cast<int>(sweep.missing.size()), sweep,
            "dropped_nonpositive differs from the missing rows listed");
    missing_rows += sweep.dropped_nonpositive;
    for (const DwellPoint& point : sweep.points) {
      const std::string at = "line " + std::to_string(point.source_line) + ": ";
      Require(PositiveFinite(point.drive_frequency_rad_s), sweep, at + "drive frequency");
      Require(PositiveFinite(point.a_base), sweep, at + "a_base");
      Require(PositiveFinite(point.amplitude), sweep, at + "amplitude");
      Require(!point.phase_rad || std::isfinite(*point.phase_rad), sweep, at + "phase");
      Require(!point.sigma || PositiveFinite(*point.sigma), sweep, at + "sigma");
      Require(!point.a_base_sigma || PositiveFinite(*point.a_base_sigma), sweep,
              at + "a_base_sigma");
      Require(sweep.kind != SweepKind::kFrequency ||
                  point.a_base_sigma == sweep.points.front().a_base_sigma,
              sweep, at + "a frequency sweep's a_base_sigma differs from its first dwell's");
      Require(point.source_line >= 2, sweep, at + "source line before the first data row");
    }
    for (const MissingDwell& row : sweep.missing) {
      Require(PositiveFinite(row.drive_frequency_rad_s) && PositiveFinite(row.a_base), sweep,
              "missing row's controls");
      Require(row.points_before >= 0 && row.points_before <= static_cast<int>(sweep.points.size()),
              sweep, "missing row's position");
    }
  }
  if (loaded.dropped_nonpositive < missing_rows) {
    throw std::logic_error("LoadSweepsCsv: fewer dropped rows counted than listed");
  }
}

}  // namespace

void SweepCsvBody(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteScratchFile("sweeps.csv", data, size);
  LoadedSweeps loaded;
  try {
    loaded = LoadSweepsCsv(path);
  } catch (const InputError&) {
    return;
  }
  CheckLoadedSweeps(loaded);
  DetectJumps(JumpDetectionOptions(), &loaded.sweeps);
  for (const Sweep& sweep : loaded.sweeps) DescribeJumps(sweep);
}

}  // namespace dwellfit::fuzz
