// The rig file: every key read, and errors at their line.
#include "dwellfit/config/rig_config_reader.h"

#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

constexpr char kRig[] = R"(sample_rate_hz: 4096
record_periods: 12
settling: {tolerance: 2.0e-4, window_periods: 30, max_periods: 9000}
channels:
  skew_samples: 0.5
  response_filter_hz: 250
noise: {relative_sigma: 0.005, seed: 9}
beam:
  boundary: clamped_clamped
  mode: 1
  length_m: 0.5
  thickness_m: 1.0e-3
  gauge_position_m: 0.01
gauge: {excitation_v: 10, gain: 500, gauge_factor: 2.0}
processing: {harmonics: 5, correct_channels: false}
)";

TEST(RigConfigReader, ReadsEveryBlock) {
  const RigConfig config = ParseRigConfig(kRig, "rig.yaml");
  EXPECT_EQ(config.rig.sample_rate_hz, 4096.0);
  EXPECT_EQ(config.rig.record_periods, 12);
  EXPECT_EQ(config.rig.settle_tolerance, 2e-4);
  EXPECT_EQ(config.rig.settle_window_periods, 30);
  EXPECT_EQ(config.rig.max_settle_periods, 9000);
  EXPECT_EQ(config.rig.channels.skew_samples, 0.5);
  EXPECT_EQ(config.rig.channels.response_filter_cutoff_hz, 250.0);
  EXPECT_EQ(config.rig.channels.base_filter_cutoff_hz, 0.0);
  EXPECT_EQ(config.rig.noise_relative_sigma, 0.005);
  EXPECT_FALSE(config.rig.base_noise_relative_sigma.has_value());  // the response's
  EXPECT_EQ(config.rig.noise_seed, 9u);
  EXPECT_EQ(config.rig.gauge.boundary, BeamBoundary::kClampedClamped);
  EXPECT_EQ(config.rig.gauge.length_m, 0.5);
  EXPECT_EQ(config.rig.gauge.gain, 500.0);
  EXPECT_EQ(config.processing.harmonics, 5);
  EXPECT_FALSE(config.processing.correct_channels);
  EXPECT_EQ(config.processing.channels.skew_samples, 0.5);
  EXPECT_EQ(config.processing.gauge.thickness_m, 1e-3);
}

TEST(RigConfigReader, TheBaseChannelMayHaveItsOwnNoise) {
  std::string text = kRig;
  const std::string noise = "noise: {relative_sigma: 0.005, seed: 9}";
  text.replace(text.find(noise), noise.size(),
               "noise: {relative_sigma: 0.005, base_relative_sigma: 0, seed: 9}");
  const RigConfig config = ParseRigConfig(text, "rig.yaml");
  ASSERT_TRUE(config.rig.base_noise_relative_sigma.has_value());
  EXPECT_EQ(*config.rig.base_noise_relative_sigma, 0.0);
  text.replace(text.find("base_relative_sigma: 0,"), 23, "base_relative_sigma: 2,");
  try {
    ParseRigConfig(text, "rig.yaml");
    ADD_FAILURE() << "a base noise of 200 % was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("noise base_relative_sigma must lie in [0, 1), got 2"));
  }
}

TEST(RigConfigReader, ErrorsNameTheLineAndTheKey) {
  std::string text = kRig;
  text.replace(text.find("skew_samples: 0.5"), 17, "skew_sample: 0.5");
  try {
    ParseRigConfig(text, "rig.yaml");
    ADD_FAILURE() << "a misspelt key was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("rig.yaml:5: field 'channels.skew_sample'"));
    EXPECT_THAT(e.what(), HasSubstr("did you mean 'skew_samples'"));
  }
  text = kRig;
  text.replace(text.find("skew_samples: 0.5"), 17, "skew_samples: 1.5");
  EXPECT_THROW(ParseRigConfig(text, "rig.yaml"), InputError);
  text = kRig;
  text.replace(text.find("boundary: clamped_clamped"), 25, "boundary: pinned");
  EXPECT_THROW(ParseRigConfig(text, "rig.yaml"), InputError);
}

}  // namespace
}  // namespace dwellfit
