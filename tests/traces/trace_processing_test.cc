// Dwell points from time traces: amplitudes, the lag, and bad traces.
#include "dwellfit/estimator/traces/trace_processing.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

// A steady dwell: base a_base cos(theta), u = a cos(theta - gamma) through the
// gauge, theta = Omega t + 0.7, sampled at fs for `samples` samples.
DwellTrace SteadyDwell(const StrainGauge& gauge, double f_hz, double fs, int samples, double a_base,
                       double a, double gamma) {
  DwellTrace trace{"F0.01", SweepDirection::kUp, SweepKind::kFrequency, HzToRadPerSecond(f_hz), fs};
  for (int j = 0; j < samples; ++j) {
    const double theta = HzToRadPerSecond(f_hz) * j / fs + 0.7;
    trace.base.push_back(static_cast<float>(a_base * std::cos(theta)));
    trace.response.push_back(
        static_cast<float>(gauge.VoltageFromDisplacement(a * std::cos(theta - gamma))));
  }
  return trace;
}

TEST(TraceProcessing, AmplitudesAndLagOfASteadyDwell) {
  TraceProcessingOptions options;
  const StrainGauge gauge(options.gauge);
  // 2048 / 41.3 = 49.59 samples per period: whole periods only to a sample.
  const DwellTrace dwell = SteadyDwell(gauge, 41.3, 2048.0, 800, 0.01, 3.1e-3, 1.2);
  const ProcessedTraces out = ProcessTraces({dwell}, options);
  ASSERT_EQ(out.sweeps.size(), 1u);
  const DwellPoint& point = out.sweeps[0].points[0];
  // The window holds whole periods only to within a sample: leakage of a few 1e-4.
  EXPECT_NEAR(point.a_base / 0.01, 1.0, 5e-4);
  EXPECT_NEAR(point.amplitude / 3.1e-3, 1.0, 5e-4);
  EXPECT_NEAR(*point.phase_rad, 1.2, 1e-3);
  EXPECT_TRUE(out.warnings.empty()) << out.warnings.front();
  EXPECT_EQ(out.unsettled_dwells, 0);
}

TEST(TraceProcessing, AGrowingResponseIsWarnedUnsettled) {
  TraceProcessingOptions options;
  const StrainGauge gauge(options.gauge);
  DwellTrace dwell = SteadyDwell(gauge, 40.0, 2048.0, 1024, 0.01, 1e-3, 0.5);
  for (std::size_t j = 0; j < dwell.response.size(); ++j) {
    dwell.response[j] *= static_cast<float>(1.0 + 0.1 * j / dwell.response.size());
  }
  const ProcessedTraces out = ProcessTraces({dwell}, options);
  EXPECT_EQ(out.unsettled_dwells, 1);
  ASSERT_EQ(out.warnings.size(), 1u);
  EXPECT_THAT(out.warnings[0], HasSubstr("unsettled: dwell F0.01/up @ 40 Hz"));
}

TEST(TraceProcessing, AStrongThirdHarmonicIsWarned) {
  TraceProcessingOptions options;
  const StrainGauge gauge(options.gauge);
  DwellTrace dwell = SteadyDwell(gauge, 40.0, 2048.0, 1024, 0.01, 1e-3, 0.5);
  const double volts = gauge.VoltageFromDisplacement(1e-3);
  for (std::size_t j = 0; j < dwell.response.size(); ++j) {
    dwell.response[j] += static_cast<float>(0.1 * volts * std::cos(3 * kTwoPi * 40.0 * j / 2048.0));
  }
  const ProcessedTraces out = ProcessTraces({dwell}, options);
  ASSERT_EQ(out.warnings.size(), 1u);
  EXPECT_THAT(out.warnings[0], HasSubstr("harmonics: dwell F0.01/up @ 40 Hz"));
  EXPECT_THAT(out.warnings[0], HasSubstr("0.1"));
}

TEST(TraceProcessing, BadTracesAreClearErrors) {
  TraceProcessingOptions options;
  const StrainGauge gauge(options.gauge);
  const DwellTrace good = SteadyDwell(gauge, 40.0, 2048.0, 256, 0.01, 1e-3, 0.5);
  auto message = [&](const DwellTrace& dwell) {
    try {
      ProcessTraces({dwell}, options);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  DwellTrace short_record = good;
  short_record.base.resize(40);  // a period is 51.2 samples
  short_record.response.resize(40);
  EXPECT_THAT(message(short_record), HasSubstr("shorter than one drive period (51.2 samples)"));
  DwellTrace uneven = good;
  uneven.response.pop_back();
  EXPECT_THAT(message(uneven), HasSubstr("different lengths (base 256, response 255 samples)"));
  DwellTrace with_nan = good;
  with_nan.response[17] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THAT(message(with_nan), HasSubstr("response sample 17 is not a finite number"));
  DwellTrace empty = good;
  empty.base.clear();
  EXPECT_THAT(message(empty), HasSubstr("a channel has no samples"));
  DwellTrace silent = good;
  std::fill(silent.response.begin(), silent.response.end(), 0.0f);
  EXPECT_THAT(message(silent), HasSubstr("the response channel is constant (every sample 0)"));
  DwellTrace no_base = good;
  std::fill(no_base.base.begin(), no_base.base.end(), 0.0f);
  EXPECT_THAT(message(no_base), HasSubstr("the base channel is constant (every sample 0)"));
  // Recorded at 64 Hz, announced at 32 Hz: the record holds 4 whole periods of
  // 32 Hz and nothing at that frequency.
  DwellTrace elsewhere = SteadyDwell(gauge, 64.0, 2048.0, 256, 0.01, 1e-3, 0.5);
  elsewhere.drive_frequency_rad_s /= 2.0;
  EXPECT_THAT(message(elsewhere), HasSubstr("the response channel has no component at the drive "
                                            "frequency; check freq_hz"));
  DwellTrace slow = good;
  slow.sample_rate_hz = 200.0;  // 5 samples per period cannot hold 3 harmonics
  EXPECT_THAT(message(slow), HasSubstr("cannot resolve 3 harmonics"));
}

TEST(TraceFile, WrittenTracesReadBackAndAShortSamplesFileIsAnError) {
  TraceProcessingOptions options;
  const StrainGauge gauge(options.gauge);
  const std::string folder =
      (std::filesystem::temp_directory_path() / "dwellfit_trace_file_test").string();
  std::filesystem::remove_all(folder);
  DwellTrace second = SteadyDwell(gauge, 41.5, 2048.0, 200, 0.02, 2e-3, 0.1);
  second.sweep = "A41.5";
  second.kind = SweepKind::kAmplitude;
  second.direction = SweepDirection::kDown;
  WriteTraceSet({SteadyDwell(gauge, 40.0, 2048.0, 256, 0.01, 1e-3, 0.5), second}, folder);
  const std::vector<DwellTrace> back = ReadTraceSet(folder);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].sweep, "A41.5");
  EXPECT_EQ(back[1].kind, SweepKind::kAmplitude);
  EXPECT_EQ(back[1].direction, SweepDirection::kDown);
  EXPECT_DOUBLE_EQ(back[1].drive_frequency_rad_s, HzToRadPerSecond(41.5));
  EXPECT_EQ(back[1].source_line, 3);
  EXPECT_EQ(back[1].response, second.response);
  std::filesystem::resize_file(std::filesystem::path(folder) / kTraceSamplesFile, 100);
  try {
    ReadTraceSet(folder);
    ADD_FAILURE() << "a cut samples file was read";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("holds 100 bytes, but traces.csv announces 3648"));
  }
  std::filesystem::remove_all(folder);
}

// The failures a real test bench produces: an index and a samples file of two
// different runs (a run killed between its two writes), an index that
// announces more samples than memory holds, and a samples "file" that is a
// folder or a device.
class TraceSetOnDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::remove_all(folder_);
    const StrainGauge gauge(TraceProcessingOptions().gauge);
    dwell_ = SteadyDwell(gauge, 40.0, 2048.0, 256, 0.01, 1e-3, 0.5);
    WriteTraceSet({dwell_}, folder_.string());
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }
  std::string Refusal() {
    try {
      ReadTraceSet(folder_.string());
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  void WriteIndex(const std::string& text) {
    std::ofstream(folder_ / kTraceIndexFile, std::ios::trunc) << text;
  }

  // One folder per test: ctest runs the tests of this fixture side by side.
  const std::filesystem::path folder_ =
      std::filesystem::temp_directory_path() /
      (std::string("dwellfit_trace_set_") +
       ::testing::UnitTest::GetInstance()->current_test_info()->name());
  DwellTrace dwell_;
};

TEST_F(TraceSetOnDisk, SamplesOfAnotherRunAreRefused) {
  const std::filesystem::path other = folder_ / "other";
  DwellTrace louder = dwell_;  // the same sizes, other samples
  for (float& value : louder.response) value *= 2.0f;
  WriteTraceSet({louder}, other.string());
  std::filesystem::copy_file(other / kTraceSamplesFile, folder_ / kTraceSamplesFile,
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_THAT(Refusal(), HasSubstr("traces.csv:2: field 'samples_crc32': F0.01/up @ 40 Hz "
                                   "(traces.csv:2): the samples in traces.f32 are not the ones"));
}

TEST_F(TraceSetOnDisk, AnIndexWithoutChecksumsStillReads) {
  WriteIndex(
      "sweep,direction,kind,freq_hz,sample_rate_hz,base_samples,response_samples\n"
      "F0.01,up,frequency,40,2048,256,256\n");
  const std::vector<DwellTrace> back = ReadTraceSet(folder_.string());
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].response, dwell_.response);
}

TEST_F(TraceSetOnDisk, AHexadecimalFrequencyIsRefused) {
  WriteIndex(
      "sweep,direction,kind,freq_hz,sample_rate_hz,base_samples,response_samples\n"
      "F0.01,up,frequency,0x28,2048,256,256\n");
  EXPECT_THAT(Refusal(), HasSubstr("traces.csv:2: field 'freq_hz': expected a positive number, "
                                   "got '0x28'"));
}

TEST_F(TraceSetOnDisk, HugeAnnouncedCountsAreRefusedBeforeAllocating) {
  std::string index = "sweep,direction,kind,freq_hz,sample_rate_hz,base_samples,response_samples\n";
  for (int row = 0; row < 64; ++row) index += "F0.01,up,frequency,40,2048,1073741824,1073741824\n";
  WriteIndex(index);  // 512 GiB of samples announced
  EXPECT_THAT(Refusal(), HasSubstr("holds 2048 bytes, but traces.csv announces 549755813888"));
}

TEST_F(TraceSetOnDisk, ASamplesFileThatIsNoRegularFileIsRefused) {
  std::filesystem::remove(folder_ / kTraceSamplesFile);
  std::filesystem::create_directory(folder_ / kTraceSamplesFile);
  EXPECT_THAT(Refusal(), HasSubstr("traces.f32: is not a regular file"));
  std::filesystem::remove(folder_ / kTraceSamplesFile);
  std::filesystem::create_symlink("/dev/zero", folder_ / kTraceSamplesFile);
  EXPECT_THAT(Refusal(), HasSubstr("traces.f32: is not a regular file"));
  std::filesystem::remove(folder_ / kTraceSamplesFile);
  ASSERT_EQ(::mkfifo((folder_ / kTraceSamplesFile).c_str(), 0600), 0);  // a read would block
  EXPECT_THAT(Refusal(), HasSubstr("traces.f32: is not a regular file"));
}

}  // namespace
}  // namespace dwellfit
