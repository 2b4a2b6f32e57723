#include "dwellfit/estimator/data/csv_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>

#include "dwellfit/estimator/data/sweep_csv_writer.h"

namespace dwellfit {
namespace {

// The header line, then rows of every kind of field: labels, integers,
// empty fields, and numbers as their shortest round-trip text.
TEST(CsvTextTest, WritesTheHeaderAndRowsOfEveryKindOfField) {
  CsvText csv("sweep,segment,a,fold", 0);
  csv.Text("L0.060g");
  csv.Integer(-1);
  csv.Number(3.6119182382678226e-05);
  csv.Empty();
  csv.EndRow();
  csv.Text("");
  csv.Integer(12);
  csv.Number(41.5);
  csv.Text("jump_up");
  csv.EndRow();
  EXPECT_EQ(std::move(csv).Release(),
            "sweep,segment,a,fold\n"
            "L0.060g,-1,3.6119182382678226e-05,\n"
            ",12,41.5,jump_up\n");
}

// No header, a row of one field.
TEST(CsvTextTest, WithoutAHeaderStartsWithTheFirstRow) {
  CsvText csv("", 4);
  csv.Number(0.5);
  csv.EndRow();
  EXPECT_EQ(std::move(csv).Release(), "0.5\n");
}

// Each number reads back as the same double and is FormatRoundTrip's text,
// from the extremes to the CSV files' sizes; not-a-number and the infinities
// are written as such.
TEST(CsvTextTest, NumbersReadBackAsTheSameDouble) {
  const double values[] = {0.0,
                           -0.0,
                           155.05498937131532,
                           -89.999999999999986,
                           1.0 / 3.0,
                           std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::lowest()};
  CsvText csv("", 0);
  std::string expected;
  for (double value : values) {
    csv.Number(value);
    expected += FormatRoundTrip(value) + ",";
  }
  csv.Number(std::numeric_limits<double>::quiet_NaN());
  csv.Number(-std::numeric_limits<double>::infinity());
  csv.EndRow();
  expected += "nan,-inf\n";
  const std::string text = std::move(csv).Release();
  EXPECT_EQ(text, expected);
  const char* at = text.c_str();
  for (double value : values) {
    char* end = nullptr;
    const double back = std::strtod(at, &end);
    EXPECT_EQ(back, value);
    EXPECT_EQ(std::signbit(back), std::signbit(value));
    ASSERT_EQ(*end, ',');
    at = end + 1;
  }
}

// Far more text than the expected length: the buffer grows and nothing is
// lost, the same text as with room for all of it at once.
TEST(CsvTextTest, GrowsPastTheExpectedLength) {
  CsvText small("n,x", 1);
  CsvText roomy("n,x", 1 << 20);
  for (int i = 0; i < 5000; ++i) {
    for (CsvText* csv : {&small, &roomy}) {
      csv->Integer(i);
      csv->Number(std::sqrt(static_cast<double>(i)));
      csv->EndRow();
    }
  }
  const std::string text = std::move(small).Release();
  EXPECT_EQ(text, std::move(roomy).Release());
  EXPECT_EQ(text.substr(0, 12), "n,x\n0,0\n1,1\n");
  const std::string last = "4999,70.70360669725413\n";
  EXPECT_EQ(text.substr(text.size() - last.size()), last);
}

}  // namespace
}  // namespace dwellfit
