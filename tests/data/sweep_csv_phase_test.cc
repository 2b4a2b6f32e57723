// The sweeps CSV writer's phase column: written when every dwell has a lag,
// read back as the same numbers, all or nothing.
#include <filesystem>
#include <sstream>
#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

Sweep TwoDwells() {
  Sweep sweep;
  sweep.id = "F0.01";
  for (double f : {40.0, 40.1}) {
    DwellPoint point;
    point.drive_frequency_rad_s = HzToRadPerSecond(f);
    point.a_base = 0.01;
    point.amplitude = 1e-3 * f;
    point.phase_rad = 0.1 * f;
    sweep.points.push_back(point);
  }
  return sweep;
}

TEST(SweepCsvPhase, PhaseColumnRoundTrips) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "dwellfit_sweep_csv_phase_test.csv").string();
  WriteSweepsCsvFile({TwoDwells()}, path);
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  ASSERT_EQ(loaded.sweeps[0].points.size(), 2u);
  EXPECT_EQ(*loaded.sweeps[0].points[1].phase_rad, 0.1 * 40.1);
  std::ostringstream text;
  WriteSweepsCsv({TwoDwells()}, &text);
  EXPECT_EQ(text.str().substr(0, text.str().find('\n')),
            "sweep,direction,freq_hz,a_base,a,phase_rad");
  std::filesystem::remove(path);
}

TEST(SweepCsvPhase, APhaseOnSomeDwellsOnlyIsAnError) {
  std::vector<Sweep> sweeps = {TwoDwells()};
  sweeps[0].points[0].phase_rad.reset();
  std::ostringstream text;
  EXPECT_THROW(WriteSweepsCsv(sweeps, &text), InputError);
}

}  // namespace
}  // namespace dwellfit
