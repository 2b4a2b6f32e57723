// The UFF data set 58 reader (estimator/traces/uff58.h) on files written
// elsewhere (pyuff's sample files, tests/data/uff/README.md) and on hostile
// or broken input; the UFF trace set (uff58_traces.h) against the native
// trace set of the virtual beam.
#include "dwellfit/estimator/traces/uff58.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/traces/trace_processing.h"
#include "dwellfit/estimator/traces/uff58_traces.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

const std::string kSource = DWELLFIT_SOURCE_DIR;
const std::string kUffData = kSource + "/tests/data/uff/";

// The message of the InputError `read` throws ("" when it throws none).
template <typename Read>
std::string ErrorOf(Read read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Sample_UFF58_ascii.uff and Sample_UFF58b_bin.uff hold one microphone
// channel, 79292 single-precision values at 1.52588E-05 s in Pa.
void ExpectMicrophoneHeader(const Uff58Record& r) {
  EXPECT_EQ(r.id_lines[0], "Mic 01.0Scalar");
  EXPECT_EQ(r.id_lines[2], "18-Apr-16 13:49:58");
  EXPECT_EQ(r.function_type, 1);
  EXPECT_EQ(r.response_entity, "Mic 01");
  EXPECT_EQ(r.response_node, 0);
  EXPECT_EQ(r.response_direction, 1);
  EXPECT_EQ(r.reference_entity, "");
  EXPECT_EQ(r.ordinate_data_type, 2);
  EXPECT_EQ(r.value_count, 79292);
  EXPECT_EQ(r.abscissa_spacing, 1);
  EXPECT_EQ(r.abscissa_min, 0.0);
  EXPECT_DOUBLE_EQ(r.abscissa_increment, 1.52588e-05);
  EXPECT_EQ(r.abscissa.specific_data_type, 17);
  EXPECT_EQ(r.abscissa.label, "time");
  EXPECT_EQ(r.abscissa.units, "s");
  EXPECT_EQ(r.ordinate.specific_data_type, 21);
  EXPECT_EQ(r.ordinate.label, "Pressure");
  EXPECT_EQ(r.ordinate.units, "Pa");
  EXPECT_EQ(r.denominator.specific_data_type, 0);
  EXPECT_EQ(r.denominator.units, "");
  ASSERT_EQ(r.values.size(), 79292u);
}

TEST(Uff58Test, ReadsPyuffAsciiSample) {
  const auto records = ReadUff58File(kUffData + "Sample_UFF58_ascii.uff");
  ASSERT_EQ(records.size(), 1u);
  const Uff58Record& r = records[0];
  EXPECT_FALSE(r.binary);
  EXPECT_EQ(r.line, 2);
  ExpectMicrophoneHeader(r);
  // The first and last values as the file's data lines print them.
  EXPECT_DOUBLE_EQ(r.values.front(), -1.47553e-02);
  EXPECT_DOUBLE_EQ(r.values[6], -1.44522e-02);
  EXPECT_DOUBLE_EQ(r.values.back(), -4.31469e-03);
}

TEST(Uff58Test, ReadsPyuffBinarySampleToTheAsciiValues) {
  const auto binary = ReadUff58File(kUffData + "Sample_UFF58b_bin.uff");
  const auto ascii = ReadUff58File(kUffData + "Sample_UFF58_ascii.uff");
  ASSERT_EQ(binary.size(), 1u);
  EXPECT_TRUE(binary[0].binary);
  ExpectMicrophoneHeader(binary[0]);
  // pyuff's test_read_58b_binary_vs_58_ascii: the same data to 6 decimals
  // (the ASCII file prints 6 significant digits of the float32 values).
  for (std::size_t i = 0; i < ascii[0].values.size(); ++i) {
    ASSERT_NEAR(binary[0].values[i], ascii[0].values[i], 1.5e-6) << "value " << i;
  }
}

TEST(Uff58Test, ReadsCatmanTimeHistoryWithPaddedLinesAndUtf8Units) {
  const auto records = ReadUff58File(kUffData + "time-history-not-all-columns-filled.uff");
  ASSERT_EQ(records.size(), 1u);
  const Uff58Record& r = records[0];
  EXPECT_EQ(r.line, 2);
  EXPECT_EQ(r.id_lines[0], "1x : m/s\u00b2");
  EXPECT_EQ(r.id_lines[1], "UFF58 file created by HBM catman");
  EXPECT_EQ(r.value_count, 13);
  EXPECT_DOUBLE_EQ(r.abscissa_increment, 5e-5);
  EXPECT_EQ(r.abscissa.units, "s");
  EXPECT_EQ(r.ordinate.specific_data_type, 1);
  EXPECT_EQ(r.ordinate.label, "1x");
  EXPECT_EQ(r.ordinate.units, "m/s\u00b2");
  ASSERT_EQ(r.values.size(), 13u);
  EXPECT_DOUBLE_EQ(r.values.front(), -3.81956);
  EXPECT_DOUBLE_EQ(r.values[6], -3.90210);
  EXPECT_DOUBLE_EQ(r.values.back(), -5.84096);
}

TEST(Uff58Test, ReadsDoublePrecisionBinaryAsTheSineItsHeaderNames) {
  // binary8byte.uff: "sine 5 Hz", 250 doubles at 0.01 s, in g.
  const auto records = ReadUff58File(kUffData + "binary8byte.uff");
  ASSERT_EQ(records.size(), 1u);
  const Uff58Record& r = records[0];
  EXPECT_TRUE(r.binary);
  EXPECT_EQ(r.response_entity, "sine 5 Hz");
  EXPECT_EQ(r.response_node, 1);
  EXPECT_EQ(r.ordinate_data_type, 4);
  EXPECT_EQ(r.value_count, 250);
  EXPECT_DOUBLE_EQ(r.abscissa_increment, 0.01);
  EXPECT_EQ(r.ordinate.specific_data_type, 12);
  EXPECT_EQ(r.ordinate.label, "acc (g)");
  EXPECT_EQ(r.ordinate.units, "g");
  ASSERT_EQ(r.values.size(), 250u);
  // The sine was evaluated in single precision: its argument's rounding
  // grows with t, to 7.4e-6 at the last sample (2.49 s).
  const double kPi = 3.14159265358979323846;
  for (std::size_t i = 0; i < r.values.size(); ++i) {
    ASSERT_NEAR(r.values[i], std::sin(2 * kPi * 5.0 * 0.01 * static_cast<double>(i)), 1e-5) << i;
  }
}

// A short channel as a data set 58.
// Values exactly representable in single precision, so that every form
// reads back exactly.
Uff58Record ShortChannel(int type) {
  Uff58Record r;
  r.id_lines[0] = "channel";
  r.function_type = 1;
  r.function_id = 7;
  r.ordinate_data_type = type;
  r.values = {1.5, -2.25, 0.0078125, 4.0, 5.0, 6.0, 7.125};
  r.value_count = 7;
  r.abscissa_increment = 1.0 / 1024;
  r.abscissa = {17, 0, 0, 0, "Time", "s"};
  r.ordinate = {12, 0, 0, 0, "base", "g"};
  return r;
}

TEST(Uff58Test, WritesWhatItReadsAndSkipsOtherDataSets) {
  for (const bool binary : {false, true}) {
    for (const int type : {2, 4}) {
      std::string text = "    -1\n   151\nmodel\n    -1\n";  // a header set, skipped
      AppendUff58(ShortChannel(type), binary, &text);
      text += "    -1\n   164\n         1SI\n    -1\n";
      const auto records = ParseUff58(text, "short.uff");
      ASSERT_EQ(records.size(), 1u);
      EXPECT_EQ(records[0].line, 6);
      EXPECT_EQ(records[0].binary, binary);
      EXPECT_EQ(records[0].function_id, 7);
      EXPECT_EQ(records[0].ordinate.units, "g");
      EXPECT_EQ(records[0].values, ShortChannel(type).values);
    }
  }
}

TEST(Uff58Test, ReadsBigEndianBinary) {
  for (const int type : {2, 4}) {
    std::string text;
    AppendUff58(ShortChannel(type), true, &text);
    // The header's byte ordering (columns 8-13) to 2, and each value's bytes
    // reversed.
    const std::size_t header = text.find("    58b     1     2");
    ASSERT_NE(header, std::string::npos);
    text[header + 12] = '2';
    const std::size_t size = type == 2 ? 4 : 8;
    const std::size_t values = text.size() - 7 - 7 * size;
    for (std::size_t i = 0; i < 7; ++i) {
      std::reverse(text.begin() + values + i * size, text.begin() + values + (i + 1) * size);
    }
    const auto records = ParseUff58(text, "big.uff");
    ASSERT_EQ(records.size(), 1u);
    EXPECT_EQ(records[0].values, ShortChannel(type).values);
  }
}

TEST(Uff58Test, NamesTheLineAndFieldOfABadAsciiValue) {
  std::string text;
  AppendUff58(ShortChannel(2), false, &text);
  text.replace(text.find("-2.25000E+00"), 12, "-2.2500x+00 ");
  EXPECT_THAT(ErrorOf([&] { ParseUff58(text, "bad.uff"); }),
              HasSubstr("bad.uff:14: field 'value 2': expected a finite number in columns 14-26"));
}

TEST(Uff58Test, NamesTheByteOffsetOfATruncatedBinaryDataSet) {
  std::string text;
  AppendUff58(ShortChannel(2), true, &text);
  const std::size_t values_at = text.size() - 7 - 28;  // 7 floats, then "    -1\n"
  text.resize(values_at + 10);
  EXPECT_THAT(ErrorOf([&] { ParseUff58(text, "cut.uff"); }),
              HasSubstr("cut.uff: field 'number of bytes (58b header)': at byte offset " +
                        std::to_string(values_at) +
                        ": announces 28 bytes of values, the file "
                        "holds 10 more"));
}

TEST(Uff58Test, RefusesAHostileCountBeforeAllocating) {
  std::string text;
  AppendUff58(ShortChannel(4), false, &text);
  text.replace(text.find("         4         7") + 10, 10, "9999999999");
  EXPECT_THAT(ErrorOf([&] { ParseUff58(text, "huge.uff"); }),
              HasSubstr("huge.uff:9: field 'number of values (record 7)': announces 9999999999 "
                        "values, more than the"));
}

TEST(Uff58Test, RefusesWhatIsNoUniversalFile) {
  EXPECT_THAT(ErrorOf([] { ParseUff58("sweep,direction\n", "x.csv"); }),
              HasSubstr("x.csv:1: expected '    -1' opening a data set"));
  EXPECT_THAT(ErrorOf([] { ParseUff58("    -1\n    58\nid\n", "short.uff"); }),
              HasSubstr("short.uff:3: field 'ID line': the file ends inside a data set 58"));
  EXPECT_THAT(ErrorOf([] { ParseUff58("    -1\n   151\nmodel\n", "open.uff"); }),
              HasSubstr("the data set at line 2 has no closing '    -1' line"));
}

// The virtual beam's UFF renditions (datasets/virtual-beam/traces-uff/).
const std::string kBeam = kSource + "/datasets/virtual-beam/";

void ExpectSameDwellPoints(const ProcessedTraces& a, const ProcessedTraces& b, double relative) {
  ASSERT_EQ(a.sweeps.size(), b.sweeps.size());
  for (std::size_t s = 0; s < a.sweeps.size(); ++s) {
    ASSERT_EQ(a.sweeps[s].points.size(), b.sweeps[s].points.size());
    for (std::size_t i = 0; i < a.sweeps[s].points.size(); ++i) {
      const DwellPoint& p = a.sweeps[s].points[i];
      const DwellPoint& q = b.sweeps[s].points[i];
      EXPECT_NEAR(q.drive_frequency_rad_s, p.drive_frequency_rad_s,
                  relative * p.drive_frequency_rad_s);
      EXPECT_NEAR(q.a_base, p.a_base, relative * p.a_base);
      EXPECT_NEAR(q.amplitude, p.amplitude, relative * p.amplitude);
      EXPECT_NEAR(*q.phase_rad, *p.phase_rad, relative * std::abs(*p.phase_rad));
    }
  }
}

TEST(Uff58TracesTest, BinaryRenditionGivesTheNativeDwells) {
  const auto native = ReadTraceSet(kBeam + "traces");
  const auto uff = ReadUffTraceSet(kBeam + "traces-uff/virtual-beam-58b.csv");
  ASSERT_EQ(uff.size(), native.size());
  EXPECT_EQ(uff[0].sample_rate_hz, 2048.0);  // 1/4.88281E-04 s read as 2048 Hz
  const TraceProcessingOptions options;
  ExpectSameDwellPoints(ProcessTraces(native, options), ProcessTraces(uff, options), 1e-6);
}

TEST(Uff58TracesTest, AsciiAndBinaryOfTheSameDwellsAreIdentical) {
  const auto ascii = ReadUffTraceSet(kBeam + "traces-uff/first-dwells-58.csv");
  auto binary = ReadUffTraceSet(kBeam + "traces-uff/virtual-beam-58b.csv");
  ASSERT_GE(binary.size(), ascii.size());
  binary.resize(ascii.size());
  for (std::size_t i = 0; i < ascii.size(); ++i) {
    EXPECT_EQ(ascii[i].base, binary[i].base);
    EXPECT_EQ(ascii[i].response, binary[i].response);
    EXPECT_EQ(ascii[i].sample_rate_hz, binary[i].sample_rate_hz);
    EXPECT_EQ(ascii[i].drive_frequency_rad_s, binary[i].drive_frequency_rad_s);
  }
  const TraceProcessingOptions options;
  ExpectSameDwellPoints(ProcessTraces(ascii, options), ProcessTraces(binary, options), 0.0);
}

TEST(Uff58TracesTest, RefusesAChannelInAnotherUnit) {
  const std::string folder = std::string(DWELLFIT_BINARY_DIR) + "/uff58_units";
  std::filesystem::create_directories(folder);
  auto dwells = ReadTraceSet(kBeam + "traces");
  dwells.resize(1);
  WriteUffTraceSet(dwells, folder + "/one.uff", folder + "/one.csv", true, "m/s^2");
  std::ofstream(folder + "/g.csv") << "sweep,direction,kind,freq_hz,file,base,response,base_unit\n"
                                   << "F0.01,up,frequency,38,one.uff,fid:1,fid:2,g\n";
  EXPECT_THAT(ErrorOf([&] { ReadUffTraceSet(folder + "/g.csv"); }),
              HasSubstr("g.csv:2: field 'base': the data set 58 at line 2 of " + folder +
                        "/one.uff is in 'm/s^2' where this channel must be in 'g'"));
  std::ofstream(folder + "/swapped.csv")
      << "sweep,direction,kind,freq_hz,file,base,response,base_unit\n"
      << "F0.01,up,frequency,38,one.uff,fid:1,fid:1,m/s^2\n";
  EXPECT_THAT(ErrorOf([&] { ReadUffTraceSet(folder + "/swapped.csv"); }),
              HasSubstr("field 'response': the data set 58 at line 2 of " + folder +
                        "/one.uff is in 'm/s^2' where this channel must be in 'V'"));
}

TEST(Uff58TracesTest, SnapsOnlyRatesWithinTheIncrementsDigits) {
  EXPECT_EQ(SampleRateFromIncrement(4.88281e-04), 2048.0);
  EXPECT_EQ(SampleRateFromIncrement(1.52588e-05), 65536.0);
  EXPECT_DOUBLE_EQ(SampleRateFromIncrement(1.0 / 1000.5), 1000.5);
}

}  // namespace
}  // namespace dwellfit
