#include "dwellfit/estimator/data/sweep_csv_writer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {
namespace {

// FormatRoundTrip's text reads back as the same double, for values of every
// size the CSV files carry (amplitudes near 1e-6 m, frequencies in Hz,
// phases in degrees) and the extremes.
TEST(SweepCsvWriterTest, FormatRoundTripGivesTheShortestTextThatReadsBack) {
  const double values[] = {0.0,
                           -0.0,
                           3.6119182382678226e-05,
                           155.05498937131532,
                           41.5,
                           -89.999999999999986,
                           1.0 / 3.0,
                           6.02214076e23,
                           std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::lowest()};
  for (double value : values) {
    const std::string text = FormatRoundTrip(value);
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), value) << text;
    EXPECT_EQ(std::signbit(std::strtod(text.c_str(), nullptr)), std::signbit(value)) << text;
  }
  EXPECT_EQ(FormatRoundTrip(41.5), "41.5");
  EXPECT_EQ(FormatRoundTrip(1e-6), "1e-06");
}

// A frequency sweep whose dwells share one level and its standard deviation,
// and an amplitude sweep whose dwells each have their own (0.5 % of the
// level, divided by an irrational so that every digit matters).
std::vector<Sweep> SweepsWithLevelSigma() {
  Sweep frequency;
  frequency.id = "F0.01";
  for (double f : {40.0, 40.1, 40.2}) {
    frequency.points.push_back(DwellPoint{HzToRadPerSecond(f), 0.01, 1e-4 * f});
    frequency.points.back().a_base_sigma = 0.005 * 0.01 / std::sqrt(3.0);
  }
  Sweep amplitude;
  amplitude.id = "A41.5";
  amplitude.kind = SweepKind::kAmplitude;
  for (double a_base : {0.011, 0.013, 0.017}) {
    amplitude.points.push_back(DwellPoint{HzToRadPerSecond(41.5), a_base, 0.3 * a_base});
    amplitude.points.back().a_base_sigma = 0.005 * a_base / std::sqrt(2.0);
  }
  return {frequency, amplitude};
}

std::string Write(const std::vector<Sweep>& sweeps) {
  std::ostringstream text;
  WriteSweepsCsv(sweeps, &text);
  return text.str();
}

// The message of the InputError that writing `sweeps` throws ("" if none).
std::string WriteError(const std::vector<Sweep>& sweeps) {
  try {
    Write(sweeps);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(SweepCsvWriterTest, LevelSigmaColumnRoundTripsToTheLastBit) {
  const std::vector<Sweep> sweeps = SweepsWithLevelSigma();
  const std::string path = ::testing::TempDir() + "dwellfit_writer_level_sigma.csv";
  WriteSweepsCsvFile(sweeps, path);
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  std::filesystem::remove(path);
  EXPECT_EQ(Write(sweeps).substr(0, Write(sweeps).find('\n')),
            "sweep,direction,freq_hz,a_base,a,a_base_sigma");
  ASSERT_EQ(loaded.sweeps.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_EQ(loaded.sweeps[s].kind, sweeps[s].kind) << s;
    ASSERT_EQ(loaded.sweeps[s].points.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      const DwellPoint& read = loaded.sweeps[s].points[i];
      const DwellPoint& written = sweeps[s].points[i];
      ASSERT_TRUE(read.a_base_sigma.has_value()) << s << " " << i;
      EXPECT_EQ(*read.a_base_sigma, *written.a_base_sigma) << s << " " << i;
      EXPECT_EQ(read.a_base, written.a_base) << s << " " << i;
      EXPECT_EQ(read.amplitude, written.amplitude) << s << " " << i;
      EXPECT_FALSE(read.sigma.has_value());
    }
  }
}

TEST(SweepCsvWriterTest, NoLevelSigmaWritesNoColumn) {
  std::vector<Sweep> sweeps = SweepsWithLevelSigma();
  for (Sweep& sweep : sweeps) {
    for (DwellPoint& point : sweep.points) point.a_base_sigma.reset();
  }
  EXPECT_EQ(Write(sweeps).substr(0, Write(sweeps).find('\n')), "sweep,direction,freq_hz,a_base,a");
}

TEST(SweepCsvWriterTest, LevelSigmaOnSomeDwellsOnlyIsAnError) {
  std::vector<Sweep> sweeps = SweepsWithLevelSigma();
  sweeps[1].points[2].a_base_sigma.reset();
  EXPECT_THAT(WriteError(sweeps),
              ::testing::HasSubstr("5 of 6 dwells carry a level sigma (a_base_sigma); give every "
                                   "dwell a level sigma (a_base_sigma) or none"));
}

// A sweep of one level is read as a frequency sweep, whose rows must share
// one a_base_sigma: the writer refuses to write what the reader would refuse.
TEST(SweepCsvWriterTest, TwoLevelSigmasInAFrequencySweepAreAnError) {
  std::vector<Sweep> sweeps = SweepsWithLevelSigma();
  sweeps[0].points[1].a_base_sigma = 2.0 * *sweeps[0].points[1].a_base_sigma;
  EXPECT_THAT(WriteError(sweeps),
              ::testing::HasSubstr("sweep 'F0.01/up' has one level a_base but dwells with "
                                   "different a_base_sigma"));
}

}  // namespace
}  // namespace dwellfit
