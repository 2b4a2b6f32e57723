#include "estimator/sweep_csv.h"

#include <glog/logging.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include "estimator/input_error.h"
#include "residuals/model_parameters.h"

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
        // Finite in Hz, infinite in rad/s.
        BadCsvCase{"frequency_overflowing_in_rad_s",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3\nF,up,1e308,0.01,1e-3\n", 3,
                   "freq_hz", "value '1e308' is too large (infinite in rad/s)"},
        BadCsvCase{"negative_sigma",
                   "sweep,direction,freq_hz,a_base,a,sigma\nF,up,40,0.01,1e-3,-1e-5\n", 2, "sigma",
                   "sigma must be > 0"},
        BadCsvCase{"too_few_fields",
                   "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3\nF,up,41\n", 3, "",
                   "fewer fields than the header"},
        BadCsvCase{"too_many_fields", "sweep,direction,freq_hz,a_base,a\nF,up,40,0.01,1e-3,7\n", 2,
                   "", "more fields than the header"},
        BadCsvCase{"unclosed_quote", "sweep,direction,freq_hz,a_base,a\n\"F,up,40,0.01,1e-3\n", 2,
                   "", "not closed"}),
    [](const ::testing::TestParamInfo<BadCsvCase>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace dwellfit
