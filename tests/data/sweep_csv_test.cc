#include "dwellfit/estimator/data/sweep_csv.h"

#include <glog/logging.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;

// Writes `contents` to a fresh file in the test temp dir; returns its path.
std::string WriteCsv(const std::string& name, const std::string& contents) {
  const std::string path = ::testing::TempDir() + "dwellfit_sweep_csv_" + name + ".csv";
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << contents;
  out.close();
  EXPECT_TRUE(out) << "cannot write " << path;
  return path;
}

// Collects the text of every WARNING logged while it is registered.
class WarningCollector : public google::LogSink {
 public:
  WarningCollector() { google::AddLogSink(this); }
  ~WarningCollector() override { google::RemoveLogSink(this); }

  using google::LogSink::send;
  void send(google::LogSeverity severity, const char*, const char*, int,
            const google::LogMessageTime&, const char* message, size_t message_len) override {
    if (severity != google::GLOG_WARNING) return;
    std::lock_guard<std::mutex> lock(mutex_);
    warnings_.emplace_back(message, message_len);
  }

  std::vector<std::string> warnings() {
    std::lock_guard<std::mutex> lock(mutex_);
    return warnings_;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> warnings_;
};

TEST(SweepCsvTest, LoadsFrequencySweepInHzAsRadPerSecond) {
  const std::string path = WriteCsv("frequency",
                                    "sweep,direction,freq_hz,a_base,a\n"
                                    "F,up,40.0,0.01,1.5e-3\n"
                                    "F,up,40.5,0.01,2.5e-3\n"
                                    "F,up,41.0,0.01,4.0e-3\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  EXPECT_EQ(loaded.dropped_nonpositive, 0);
  EXPECT_TRUE(loaded.all_dropped.empty());
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  const Sweep& sweep = loaded.sweeps[0];
  EXPECT_EQ(sweep.id, "F");
  EXPECT_EQ(sweep.direction, SweepDirection::kUp);
  EXPECT_EQ(sweep.kind, SweepKind::kFrequency);
  EXPECT_EQ(sweep.source_file, path);
  EXPECT_EQ(sweep.dropped_nonpositive, 0);
  ASSERT_EQ(sweep.points.size(), 3u);
  EXPECT_DOUBLE_EQ(sweep.points[0].drive_frequency_rad_s, 2.0 * kPi * 40.0);
  EXPECT_DOUBLE_EQ(sweep.points[2].drive_frequency_rad_s, 2.0 * kPi * 41.0);
  EXPECT_DOUBLE_EQ(sweep.points[1].a_base, 0.01);
  EXPECT_DOUBLE_EQ(sweep.points[1].amplitude, 2.5e-3);
  EXPECT_EQ(sweep.points[0].source_line, 2);
  EXPECT_EQ(sweep.points[2].source_line, 4);
  EXPECT_FALSE(sweep.points[0].phase_rad.has_value());
  EXPECT_FALSE(sweep.points[0].sigma.has_value());
  EXPECT_FALSE(sweep.points[0].a_base_sigma.has_value());
  EXPECT_EQ(sweep.points[0].branch, Branch::kOnly);
}

TEST(SweepCsvTest, GroupsBySweepAndDirectionInOrderOfFirstAppearance) {
  // Columns in another order, quoted and padded fields, a blank line, CRLF.
  const std::string path = WriteCsv("grouping",
                                    "a, a_base ,direction,sweep,freq_hz\r\n"
                                    "1e-3,0.01,down,B,42\r\n"
                                    "2e-3,0.01,up,A,40\r\n"
                                    "\r\n"
                                    "3e-3,0.01,down,B,41\r\n"
                                    "4e-3, 0.01 ,up,\"A\",41\r\n"
                                    "5e-3,0.02,up,B,41\r\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 3u);
  EXPECT_EQ(loaded.sweeps[0].Name(), "B/down");
  EXPECT_EQ(loaded.sweeps[1].Name(), "A/up");
  EXPECT_EQ(loaded.sweeps[2].Name(), "B/up");
  const Sweep& b_down = loaded.sweeps[0];
  ASSERT_EQ(b_down.points.size(), 2u);
  EXPECT_DOUBLE_EQ(b_down.points[0].amplitude, 1e-3);
  EXPECT_DOUBLE_EQ(b_down.points[1].amplitude, 3e-3);
  EXPECT_EQ(b_down.points[0].source_line, 2);
  EXPECT_EQ(b_down.points[1].source_line, 5);  // line 4 is blank
  const Sweep& a_up = loaded.sweeps[1];
  ASSERT_EQ(a_up.points.size(), 2u);
  EXPECT_EQ(a_up.points[1].source_line, 6);
  EXPECT_DOUBLE_EQ(a_up.points[1].drive_frequency_rad_s, HzToRadPerSecond(41.0));
  EXPECT_DOUBLE_EQ(a_up.points[1].a_base, 0.01);
  ASSERT_EQ(loaded.sweeps[2].points.size(), 1u);
  EXPECT_DOUBLE_EQ(loaded.sweeps[2].points[0].a_base, 0.02);
}

TEST(SweepCsvTest, KindFollowsTheControlThatVaries) {
  const std::string path = WriteCsv("kinds",
                                    "sweep,direction,freq_hz,a_base,a\n"
                                    "AMP,up,41.5,0.002,1e-4\n"
                                    "AMP,up,41.5,0.004,2e-4\n"
                                    "AMP,up,41.5,0.008,4e-4\n"
                                    "FRQ,down,46,0.01,1e-4\n"
                                    "FRQ,down,45,0.01,2e-4\n"
                                    "REP,up,41,0.01,3e-3\n"
                                    "REP,up,41,0.01,3.1e-3\n"
                                    "ONE,up,41,0.01,3e-3\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 4u);
  EXPECT_EQ(loaded.sweeps[0].kind, SweepKind::kAmplitude);
  EXPECT_EQ(loaded.sweeps[1].kind, SweepKind::kFrequency);
  EXPECT_EQ(loaded.sweeps[2].kind, SweepKind::kFrequency);  // repeated dwells
  EXPECT_EQ(loaded.sweeps[3].kind, SweepKind::kFrequency);  // single dwell
  EXPECT_DOUBLE_EQ(loaded.sweeps[0].Control(loaded.sweeps[0].points[2]), 0.008);
}

TEST(SweepCsvTest, ConvertsPhaseDegreesToRadiansAndReadsSigma) {
  const std::string path = WriteCsv("phase_deg",
                                    "sweep,direction,freq_hz,a_base,a,phase_deg,sigma\n"
                                    "F,up,40,0.01,1e-3,90,1e-5\n"
                                    "F,up,41,0.01,2e-3,-45,2e-5\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  const auto& points = loaded.sweeps[0].points;
  ASSERT_EQ(points.size(), 2u);
  ASSERT_TRUE(points[0].phase_rad.has_value());
  EXPECT_DOUBLE_EQ(*points[0].phase_rad, kPi / 2.0);
  EXPECT_DOUBLE_EQ(*points[1].phase_rad, -kPi / 4.0);
  ASSERT_TRUE(points[1].sigma.has_value());
  EXPECT_DOUBLE_EQ(*points[1].sigma, 2e-5);
}

// a_base_sigma is the level's standard deviation in a_base's unit: read as
// written (not converted, not mixed up with sigma). A frequency sweep's rows
// state one value; an amplitude sweep's rows each their own, repeats of a
// level included.
TEST(SweepCsvTest, ReadsTheLevelsStandardDeviationInTheUnitOfABase) {
  const std::string path = WriteCsv("a_base_sigma",
                                    "a_base_sigma,sweep,direction,freq_hz,a_base,a,sigma\n"
                                    "2.5e-5,F,up,40,0.01,1e-3,1e-5\n"
                                    "2.5e-5,F,up,41,0.01,2e-3,1e-5\n"
                                    "2.5e-5,F,up,42,0.01,0,1e-5\n"
                                    "1e-5,A,up,41.5,0.01,1e-3,1e-5\n"
                                    "2e-5,A,up,41.5,0.01,1.1e-3,1e-5\n"
                                    "3e-5,A,up,41.5,0.03,3e-3,1e-5\n"
                                    "4e-5,A,up,41.5,0.05,4e-3,1e-5\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 2u);
  const Sweep& frequency = loaded.sweeps[0];
  EXPECT_EQ(frequency.kind, SweepKind::kFrequency);
  ASSERT_EQ(frequency.points.size(), 2u);
  for (const DwellPoint& point : frequency.points) {
    ASSERT_TRUE(point.a_base_sigma.has_value());
    EXPECT_EQ(*point.a_base_sigma, 2.5e-5);
    EXPECT_EQ(point.a_base, 0.01);
    EXPECT_EQ(point.sigma, 1e-5);
  }
  const Sweep& amplitude = loaded.sweeps[1];
  EXPECT_EQ(amplitude.kind, SweepKind::kAmplitude);
  ASSERT_EQ(amplitude.points.size(), 4u);
  const double expected[] = {1e-5, 2e-5, 3e-5, 4e-5};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(amplitude.points[i].a_base_sigma, expected[i]) << i;
  }
}

TEST(SweepCsvTest, ReadsPhaseInRadiansUnchanged) {
  const std::string path = WriteCsv("phase_rad",
                                    "phase_rad,sweep,direction,freq_hz,a_base,a\n"
                                    "1.25,F,up,40,0.01,1e-3\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  ASSERT_TRUE(loaded.sweeps[0].points[0].phase_rad.has_value());
  EXPECT_DOUBLE_EQ(*loaded.sweeps[0].points[0].phase_rad, 1.25);
}

TEST(SweepCsvTest, DropsNonPositiveAmplitudesCountsAndWarnsPerSweep) {
  const std::string path = WriteCsv("dropped",
                                    "sweep,direction,freq_hz,a_base,a\n"
                                    "H,up,40,0.09,1e-3\n"
                                    "H,up,41,0.09,4e-3\n"
                                    "H,up,42,0.09,0\n"
                                    "H,up,43,0.09,-1e-6\n"
                                    "H,up,44,0.09,0.0\n"
                                    "K,up,40,0.01,2e-3\n"
                                    "Z,down,44,0.09,0\n"
                                    "Z,down,43,0.09,0\n");
  WarningCollector collector;
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  EXPECT_EQ(loaded.dropped_nonpositive, 5);
  EXPECT_THAT(loaded.all_dropped, ElementsAre("Z/down"));
  ASSERT_EQ(loaded.sweeps.size(), 2u);
  EXPECT_EQ(loaded.sweeps[0].Name(), "H/up");
  EXPECT_EQ(loaded.sweeps[0].dropped_nonpositive, 3);
  ASSERT_EQ(loaded.sweeps[0].points.size(), 2u);
  EXPECT_EQ(loaded.sweeps[0].points[1].source_line, 3);
  EXPECT_EQ(loaded.sweeps[1].Name(), "K/up");
  EXPECT_EQ(loaded.sweeps[1].dropped_nonpositive, 0);

  const std::vector<std::string> warnings = collector.warnings();
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_THAT(warnings[0], HasSubstr("H/up"));
  EXPECT_THAT(warnings[0], HasSubstr("dropped 3 of 5 rows"));
  EXPECT_THAT(warnings[0], HasSubstr("3 of them after the last measured row"));
  EXPECT_THAT(warnings[1], HasSubstr("Z/down"));
  EXPECT_THAT(warnings[1], HasSubstr("all 2 rows"));
  EXPECT_THAT(warnings[1], HasSubstr("left out"));
}

TEST(SweepCsvTest, KeepsWhereEachMissingRowFellAmongTheDwells) {
  // Amplitude sweep: a_base is the control. Missing rows before the first
  // dwell, between dwells and after the last one.
  const std::string path = WriteCsv("missing_rows",
                                    "sweep,direction,freq_hz,a_base,a\n"
                                    "A,up,41.5,0.010,0\n"
                                    "A,up,41.5,0.020,1e-3\n"
                                    "A,up,41.5,0.030,-1\n"
                                    "A,up,41.5,0.040,4e-3\n"
                                    "A,up,41.5,0.050,0\n"
                                    "A,up,41.5,0.060,0\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  const Sweep& sweep = loaded.sweeps[0];
  EXPECT_EQ(sweep.kind, SweepKind::kAmplitude);
  ASSERT_EQ(sweep.points.size(), 2u);
  EXPECT_EQ(sweep.dropped_nonpositive, 4);
  ASSERT_EQ(sweep.missing.size(), 4u);
  std::vector<int> points_before, lines;
  std::vector<double> controls;
  for (const MissingDwell& row : sweep.missing) {
    points_before.push_back(row.points_before);
    lines.push_back(row.source_line);
    controls.push_back(sweep.Control(row));
    EXPECT_DOUBLE_EQ(row.drive_frequency_rad_s, 2.0 * kPi * 41.5);
  }
  EXPECT_THAT(points_before, ElementsAre(0, 1, 2, 2));
  EXPECT_THAT(lines, ElementsAre(2, 4, 6, 7));
  EXPECT_THAT(controls, ElementsAre(0.010, 0.030, 0.050, 0.060));
}

TEST(SweepCsvTest, MissingFileSaysItCannotBeOpened) {
  const std::string path = ::testing::TempDir() + "dwellfit_no_such_file.csv";
  try {
    LoadSweepsCsv(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("cannot open"));
    EXPECT_THAT(e.what(), HasSubstr("No such file"));
  }
}

TEST(SweepCsvTest, DirectoryIsRejected) {
  const std::string path = ::testing::TempDir();
  try {
    LoadSweepsCsv(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("is a directory"));
  }
}

TEST(SweepCsvTest, CharacterDeviceIsRejectedForWhatItIs) {
  try {
    LoadSweepsCsv("/dev/null");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "/dev/null: is a character device, not a file; give the path of a sweeps CSV "
                 "file");
  }
}

TEST(SweepCsvTest, AcceptsTheRangeBoundsAndSmallSiAmplitudes) {
  // The bounds themselves, and amplitudes of a small vibration in metres.
  const std::string path = WriteCsv("bounds",
                                    "sweep,direction,freq_hz,a_base,a,sigma\n"
                                    "F,up,1e-6,1e-20,1e-20,1e-20\n"
                                    "F,up,40,1e-20,1e-12,1e-14\n"
                                    "F,up,1e9,1e-20,1e20,1e20\n"
                                    "G,down,41.5,1e20,1e3,1\n"
                                    "G,down,41.5,9.81,1e-12,1e-14\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 2u);
  ASSERT_EQ(loaded.sweeps[0].points.size(), 3u);
  EXPECT_DOUBLE_EQ(loaded.sweeps[0].points[0].drive_frequency_rad_s, HzToRadPerSecond(1e-6));
  EXPECT_DOUBLE_EQ(loaded.sweeps[0].points[1].amplitude, 1e-12);
  EXPECT_DOUBLE_EQ(loaded.sweeps[0].points[2].amplitude, 1e20);
  EXPECT_EQ(loaded.sweeps[1].kind, SweepKind::kAmplitude);
  EXPECT_DOUBLE_EQ(loaded.sweeps[1].points[0].a_base, 1e20);
}

TEST(SweepCsvTest, RepeatedControlsAndMissingRowsKeepTheOrder) {
  // Repeats are allowed in either direction; a missing row is checked too.
  const std::string path = WriteCsv("repeats",
                                    "sweep,direction,freq_hz,a_base,a\n"
                                    "F,down,42,0.01,1e-3\n"
                                    "F,down,42,0.01,1.1e-3\n"
                                    "F,down,41,0.01,0\n"
                                    "F,down,41,0.01,2e-3\n"
                                    "F,down,40,0.01,3e-3\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  EXPECT_EQ(loaded.sweeps[0].points.size(), 4u);
  EXPECT_EQ(loaded.sweeps[0].dropped_nonpositive, 1);
}

TEST(SweepCsvTest, ByteOrderMarkBeforeTheHeaderIsSkipped) {
  const std::string path = WriteCsv("bom",
                                    "\xEF\xBB\xBFsweep,direction,freq_hz,a_base,a\r\n"
                                    "F,up,40,0.01,1e-3\r\n"
                                    "F,up,41,0.01,2e-3\r\n");
  const LoadedSweeps loaded = LoadSweepsCsv(path);
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  EXPECT_EQ(loaded.sweeps[0].id, "F");
  EXPECT_EQ(loaded.sweeps[0].points.size(), 2u);
}

TEST(SweepCsvTest, ALineLongerThan16MegabytesIsRejectedWithoutEchoingIt) {
  // A 50 MB line fails the same way as one just past the reader's limit of 2^24 - 1.
  const std::string path = WriteCsv("long_line", "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01," +
                                                     std::string((1 << 24) + 16, '7') + "\n");
  try {
    LoadSweepsCsv(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path +
                  ":2: the line is longer than 2^24 - 1 bytes, which no row of a sweeps CSV is; "
                  "check that this is the sweeps file");
  }
}

TEST(SweepCsvTest, BundledDatasetsAreInMeasurementOrder) {
  // The loader rejects sweeps out of order; both datasets load, all their rows.
  for (const auto& [dataset, sweeps, rows] :
       {std::tuple<const char*, std::size_t, int>{"thesis-numerical", 8, 456},
        std::tuple<const char*, std::size_t, int>{"clamped-beam-27C", 24, 24576}}) {
    const LoadedSweeps loaded =
        LoadSweepsCsv(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/" + dataset + "/sweeps.csv");
    EXPECT_EQ(loaded.sweeps.size(), sweeps) << dataset;
    int loaded_rows = loaded.dropped_nonpositive;
    for (const Sweep& sweep : loaded.sweeps) loaded_rows += sweep.points.size();
    EXPECT_EQ(loaded_rows, rows) << dataset;
  }
}

// One malformed file: where the error must point and what it must say.
struct BadCsvCase {
  const char* name;
  const char* contents;
  int line;
  const char* field;  // "" when the error is about a whole row or file
  const char* fragment;
};

void PrintTo(const BadCsvCase& c, std::ostream* os) { *os << c.name; }

class SweepCsvErrorTest : public ::testing::TestWithParam<BadCsvCase> {};

TEST_P(SweepCsvErrorTest, ThrowsInputErrorNamingFileLineAndColumn) {
  const BadCsvCase& c = GetParam();
  const std::string path = WriteCsv(std::string("bad_") + c.name, c.contents);
  try {
    LoadSweepsCsv(path);
    FAIL() << "expected InputError for " << c.name;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), c.line) << message;
    EXPECT_EQ(e.field(), c.field) << message;
    EXPECT_THAT(message, HasSubstr(path + ":" + std::to_string(c.line) + ":"));
    if (*c.field != '\0') {
      EXPECT_THAT(message, HasSubstr(std::string("field '") + c.field + "'"));
    }
    EXPECT_THAT(message, HasSubstr(c.fragment));
  }
}

INSTANTIATE_TEST_SUITE_P(
    SweepCsvTest, SweepCsvErrorTest,
    ::testing::Values(
        BadCsvCase{"empty_file", "", 1, "", "the file is empty"},
        BadCsvCase{"header_only", "sweep,direction,freq_hz,a_base,a\n", 1, "", "no data rows"},
        BadCsvCase{"missing_column", "sweep,direction,freq_hz,a\nF,up,40,1e-3\n", 1, "a_base",
                   "required column is missing"},
        BadCsvCase{"unknown_column",
                   "sweep,direction,freq_hz,a_base,a,temp\nF,up,40,0.01,1e-3,27\n", 1, "temp",
                   "unknown column; allowed columns are sweep, direction"},
        BadCsvCase{"duplicated_column", "sweep,direction,freq_hz,a_base,a,a\n", 1, "a",
                   "appears twice"},
        BadCsvCase{"both_phase_columns",
                   "sweep,direction,freq_hz,a_base,a,phase_deg,phase_rad\nF,up,40,0.01,1e-3,9,1\n",
                   1, "phase_rad", "keep one"},
        BadCsvCase{"non_numeric",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3\n"
                   "F,up,4l.5,0.01,1e-3\n",
                   3, "freq_hz", "'4l.5' is not a number"},
        BadCsvCase{"trailing_text", "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3 m\n", 2,
                   "a", "is not a number"},
        BadCsvCase{"empty_value", "sweep,direction,freq_hz,a_base,a\nF,up,40,,1e-3\n", 2, "a_base",
                   "empty"},
        BadCsvCase{"nan_value", "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,nan\n", 2, "a",
                   "not finite"},
        BadCsvCase{"inf_value", "sweep,direction,freq_hz,a_base,a\nF,up,inf,0.01,1e-3\n", 2,
                   "freq_hz", "not finite"},
        BadCsvCase{"overflow_value", "sweep,direction,freq_hz,a_base,a\nF,up,40,1e999,1e-3\n", 2,
                   "a_base", "out of the range"},
        BadCsvCase{"zero_frequency", "sweep,direction,freq_hz,a_base,a\nF,up,0,0.01,1e-3\n", 2,
                   "freq_hz", "must be > 0"},
        BadCsvCase{"negative_frequency", "sweep,direction,freq_hz,a_base,a\nF,up,-40,0.01,1e-3\n",
                   2, "freq_hz", "must be > 0"},
        BadCsvCase{"negative_a_base", "sweep,direction,freq_hz,a_base,a\nF,up,40,-0.01,1e-3\n", 2,
                   "a_base", "a_base must be > 0"},
        BadCsvCase{"zero_a_base", "sweep,direction,freq_hz,a_base,a\nF,up,40,0,1e-3\n", 2, "a_base",
                   "a_base must be > 0"},
        BadCsvCase{"bad_direction", "sweep,direction,freq_hz,a_base,a\nF,upward,40,0.01,1e-3\n", 2,
                   "direction", "must be 'up' or 'down'"},
        BadCsvCase{"empty_sweep_id", "sweep,direction,freq_hz,a_base,a\n,up,40,0.01,1e-3\n", 2,
                   "sweep", "sweep id is empty"},
        BadCsvCase{"both_controls_vary",
                   "sweep,direction,freq_hz,a_base,a\n"
                   "F,up,40,0.01,1e-3\n"
                   "F,up,41,0.01,2e-3\n"
                   "G,up,41,0.02,2e-3\n"
                   "F,up,42,0.01,3e-3\n"
                   "F,up,43,0.02,4e-3\n",
                   6, "a_base", "sweep 'F/up' varies both freq_hz (first change at line 3)"},
        BadCsvCase{"both_controls_vary_amplitude_first",
                   "sweep,direction,freq_hz,a_base,a\n"
                   "A,down,41.5,0.05,4e-3\n"
                   "A,down,41.5,0.04,3e-3\n"
                   "A,down,41.6,0.03,2e-3\n",
                   4, "freq_hz", "and a_base (first change at line 3)"},
        BadCsvCase{"zero_sigma", "sweep,direction,freq_hz,a_base,a,sigma\nF,up,40,0.01,1e-3,0\n", 2,
                   "sigma", "sigma must be > 0"},
        BadCsvCase{"negative_sigma",
                   "sweep,direction,freq_hz,a_base,a,sigma\nF,up,40,0.01,1e-3,-1e-5\n", 2, "sigma",
                   "sigma must be > 0"},
        BadCsvCase{"too_few_fields",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3\nF,up,41\n", 3, "",
                   "fewer fields than the header"},
        BadCsvCase{"too_many_fields", "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3,7\n", 2,
                   "", "more fields than the header"},
        BadCsvCase{"unclosed_quote", "sweep,direction,freq_hz,a_base,a\n\"F,up,40,0.01,1e-3\n", 2,
                   "", "not closed"},
        // Values outside the accepted ranges (sweep_csv.h): huge, or subnormal.
        BadCsvCase{"amplitude_huge", "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e308\n", 2,
                   "a",
                   "the amplitude a 1e308 is outside the accepted range [1e-20, 1e+20], beyond "
                   "which the model's powers (a^6) and squared residuals overflow or underflow; "
                   "give a in a unit that puts it inside the range, or write 0 for a missing "
                   "measurement"},
        BadCsvCase{"amplitude_subnormal", "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-320\n",
                   2, "a", "the amplitude a 1e-320 is outside the accepted range [1e-20, 1e+20]"},
        BadCsvCase{"frequency_huge", "sweep,direction,freq_hz,a_base,a\nF,up,1e308,0.01,1e-3\n", 2,
                   "freq_hz",
                   "the drive frequency [Hz] 1e308 is outside the accepted range [1e-06, 1e+09], "
                   "beyond which the model's powers (Omega^4) and squared residuals overflow or "
                   "underflow; freq_hz is in Hz (not rad/s or kHz)"},
        BadCsvCase{"frequency_subnormal",
                   "sweep,direction,freq_hz,a_base,a\nF,up,1e-320,0.01,1e-3\n", 2, "freq_hz",
                   "the drive frequency [Hz] 1e-320 is outside the accepted range [1e-06, 1e+09]"},
        BadCsvCase{"a_base_huge", "sweep,direction,freq_hz,a_base,a\nF,up,40,2e20,1e-3\n", 2,
                   "a_base", "the base level a_base 2e20 is outside the accepted range"},
        BadCsvCase{"sigma_subnormal",
                   "sweep,direction,freq_hz,a_base,a,sigma\nF,up,40,0.01,1e-3,1e-320\n", 2, "sigma",
                   "the standard deviation sigma 1e-320 is outside the accepted range [1e-20, "
                   "1e+20]"},
        // Rows out of measurement order: never sorted, the first such row named.
        BadCsvCase{"up_sweep_shuffled",
                   "sweep,direction,freq_hz,a_base,a\n"
                   "F,up,40,0.01,1e-3\n"
                   "F,up,42,0.01,3e-3\n"
                   "F,up,41,0.01,2e-3\n"
                   "F,up,43,0.01,4e-3\n",
                   4, "freq_hz",
                   "sweep 'F/up' is an up-sweep, but freq_hz falls from 42 (line 3) to 41; rows "
                   "must be in measurement order, the control rising in an up-sweep and falling "
                   "in a down-sweep (repeats allowed). The order places the jumps, so it is not "
                   "repaired: restore the measured order (a shuffled, reversed or twice-appended "
                   "file shows this), or give a second pass its own sweep id"},
        BadCsvCase{"down_sweep_reversed",
                   "sweep,direction,freq_hz,a_base,a\n"
                   "F,down,40,0.01,1e-3\n"
                   "F,down,41,0.01,2e-3\n",
                   3, "freq_hz",
                   "sweep 'F/down' is a down-sweep, but freq_hz rises from 40 (line 2) to 41"},
        BadCsvCase{"amplitude_sweep_out_of_order",
                   "sweep,direction,freq_hz,a_base,a\n"
                   "A,up,41.5,0.01,1e-3\n"
                   "A,up,41.5,0.02,2e-3\n"
                   "A,up,41.5,0.02,2.1e-3\n"
                   "A,up,41.5,0.015,1.5e-3\n",
                   5, "a_base",
                   "sweep 'A/up' is an up-sweep, but a_base falls from 0.02 (line 4) to 0.015"},
        BadCsvCase{"appended_to_itself",
                   "sweep,direction,freq_hz,a_base,a\n"
                   "F,up,40,0.01,1e-3\nF,up,41,0.01,2e-3\nF,down,41,0.01,2e-3\n"
                   "F,down,40,0.01,1e-3\n"
                   "F,up,40,0.01,1e-3\nF,up,41,0.01,2e-3\nF,down,41,0.01,2e-3\n"
                   "F,down,40,0.01,1e-3\n",
                   6, "freq_hz",
                   "sweep 'F/up' is an up-sweep, but freq_hz falls from 41 (line 3) to 40"},
        BadCsvCase{"missing_row_out_of_order",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3\nF,up,41,0.01,0\n"
                   "F,up,39,0.01,0\n",
                   4, "freq_hz", "freq_hz falls from 41 (line 3) to 39"},
        BadCsvCase{"copied_row",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3\nF,up,41,0.01,2e-3\n"
                   "F,up,41,0.01,2e-3\n",
                   4, "",
                   "row repeats line 3 value for value (sweep 'F/up'): a copied row counts one "
                   "dwell twice and understates the uncertainty; remove it"},
        // Files that are not comma-separated with LF or CRLF line ends.
        BadCsvCase{"semicolon_separated", "sweep;direction;freq_hz;a_base;a\nF;up;40,5;0,01;1e-3\n",
                   1, "sweep;direction;freq_hz;a_base;a",
                   "unknown column; allowed columns are sweep, direction, freq_hz, a_base, a "
                   "(required) and phase_deg or phase_rad, sigma, a_base_sigma (optional); the "
                   "header reads as "
                   "one column: this file seems to separate fields by ';', but a sweeps CSV "
                   "separates them by commas (and writes numbers with a '.' decimal point): save "
                   "it as comma-separated"},
        BadCsvCase{"tab_separated", "sweep\tdirection\tfreq_hz\ta_base\ta\nF\tup\t40\t0.01\t1e-3\n",
                   1, "sweep\\tdirection\\tfreq_hz\\ta_base\\ta",
                   "this file seems to separate fields by tabs"},
        BadCsvCase{"carriage_return_line_ends",
                   "sweep,direction,freq_hz,a_base,a\rF,up,40,0.01,1e-3\rF,up,41,0.01,2e-3\r", 1,
                   "a\\rF",
                   "the lines of this file end in a carriage return alone (\\r, old Mac style): "
                   "save it with LF or CRLF line ends"},
        BadCsvCase{"decimal_comma", "sweep,direction,freq_hz,a_base,a\nF,up,40,5,0.01,1e-3\n", 2,
                   "",
                   "row has more fields than the header; give one value per header column (a "
                   "decimal comma splits a number in two: write 40.5, not 40,5)"},
        BadCsvCase{"quoted_decimal_comma",
                   "sweep,direction,freq_hz,a_base,a\nF,up,\"40,5\",0.01,1e-3\n", 2, "freq_hz",
                   "value '40,5' is not a number; write numbers with a decimal point, not a comma "
                   "(40.5, not 40,5)"},
        // Raw bytes are escaped and long values cut in messages.
        BadCsvCase{"binary_bytes",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1\x01\x02\x7f\xff\n", 2, "a",
                   "value '1\\x01\\x02\\x7F\\xFF' is not a number"},
        BadCsvCase{"binary_direction", "sweep,direction,freq_hz,a_base,a\nF,u\rp,40,0.01,1e-3\n", 2,
                   "direction", "value 'u\\rp' must be 'up' or 'down'"},
        BadCsvCase{"long_value",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,"
                   "x123456789x123456789x123456789x123456789x123456789x123456789\n",
                   2, "a",
                   "value 'x123456789x123456789x123456789x123456789... (60 bytes in all)' is not a "
                   "number"}),
    [](const ::testing::TestParamInfo<BadCsvCase>& info) { return std::string(info.param.name); });

// a_base_sigma: checked like sigma; one value per frequency sweep, the first
// row that differs named (even when the sweep turns out to be a frequency
// sweep only later, or never varies a control).
INSTANTIATE_TEST_SUITE_P(
    LevelSigma, SweepCsvErrorTest,
    ::testing::Values(
        BadCsvCase{"zero", "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,0\n",
                   2, "a_base_sigma", "the standard deviation a_base_sigma must be > 0, got 0"},
        BadCsvCase{"negative",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,-1e-4\n", 2,
                   "a_base_sigma", "the standard deviation a_base_sigma must be > 0, got -1e-4"},
        BadCsvCase{"nan", "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,nan\n",
                   2, "a_base_sigma", "value 'nan' is not finite"},
        BadCsvCase{"infinite",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,inf\n", 2,
                   "a_base_sigma", "value 'inf' is not finite"},
        BadCsvCase{"text", "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,low\n",
                   2, "a_base_sigma", "value 'low' is not a number"},
        BadCsvCase{"empty", "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,\n",
                   2, "a_base_sigma", "value is empty"},
        BadCsvCase{"huge",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,1e21\n", 2,
                   "a_base_sigma",
                   "the standard deviation a_base_sigma 1e21 is outside the accepted range "
                   "[1e-20, 1e+20], beyond which the model's powers (a_base_sigma^2) and squared "
                   "residuals overflow or underflow; a_base_sigma is in the unit of a_base"},
        BadCsvCase{"subnormal",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\nF,up,40,0.01,1e-3,1e-320\n", 2,
                   "a_base_sigma",
                   "the standard deviation a_base_sigma 1e-320 is outside the accepted range"},
        BadCsvCase{"differs_in_a_frequency_sweep",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\n"
                   "F,up,40,0.01,1e-3,2e-5\n"
                   "F,up,41,0.01,2e-3,2e-5\n"
                   "F,up,42,0.01,3e-3,3e-5\n",
                   4, "a_base_sigma",
                   "sweep 'F/up' is a frequency sweep (one level a_base), but its a_base_sigma "
                   "changes from 2e-05 (line 2) to 3e-05; the rows of a frequency sweep share one "
                   "level and so one level error: give each of them the same a_base_sigma"},
        BadCsvCase{"differs_before_the_frequency_steps",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\n"
                   "F,up,40,0.01,1e-3,2e-5\n"
                   "F,up,40,0.01,1.1e-3,3e-5\n"
                   "F,up,41,0.01,2e-3,3e-5\n",
                   3, "a_base_sigma", "changes from 2e-05 (line 2) to 3e-05"},
        BadCsvCase{"differs_in_repeated_dwells",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\n"
                   "F,up,40,0.01,1e-3,2e-5\n"
                   "G,up,40,0.02,1e-3,9e-5\n"
                   "F,up,40,0.01,1.1e-3,3e-5\n",
                   4, "a_base_sigma", "sweep 'F/up' is a frequency sweep"},
        BadCsvCase{"differs_on_a_missing_row",
                   "sweep,direction,freq_hz,a_base,a,a_base_sigma\n"
                   "F,down,41,0.01,1e-3,2e-5\n"
                   "F,down,40,0.01,0,3e-5\n",
                   3, "a_base_sigma", "changes from 2e-05 (line 2) to 3e-05"}),
    [](const ::testing::TestParamInfo<BadCsvCase>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace dwellfit
