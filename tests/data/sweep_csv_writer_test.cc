#include "dwellfit/estimator/data/sweep_csv_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

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

}  // namespace
}  // namespace dwellfit
