#include <string>

#include "dwellfit/config/sweep_selection.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

SweepSelection Parsed(const std::string& text) {
  SweepSelection selection;
  std::string error;
  EXPECT_TRUE(ParseSweepSelection(text, &selection, &error)) << error;
  return selection;
}

Sweep MakeSweep(const std::string& id, SweepDirection direction) {
  Sweep sweep;
  sweep.id = id;
  sweep.direction = direction;
  return sweep;
}

TEST(ParseSweepSelection, IdAloneSelectsBothDirections) {
  const SweepSelection both = Parsed("A41.5");
  EXPECT_EQ(both.sweep_id, "A41.5");
  EXPECT_FALSE(both.direction.has_value());
  EXPECT_EQ(both.Name(), "A41.5");
  EXPECT_TRUE(both.Selects(MakeSweep("A41.5", SweepDirection::kUp)));
  EXPECT_TRUE(both.Selects(MakeSweep("A41.5", SweepDirection::kDown)));
  EXPECT_FALSE(both.Selects(MakeSweep("A41.2", SweepDirection::kUp)));
}

TEST(ParseSweepSelection, SuffixSelectsOneDirection) {
  const SweepSelection down = Parsed("F0.01/down");
  EXPECT_EQ(down.sweep_id, "F0.01");
  EXPECT_EQ(down.direction, SweepDirection::kDown);
  EXPECT_EQ(down.Name(), "F0.01/down");
  EXPECT_EQ(down.Name(), MakeSweep("F0.01", SweepDirection::kDown).Name());
  EXPECT_TRUE(down.Selects(MakeSweep("F0.01", SweepDirection::kDown)));
  EXPECT_FALSE(down.Selects(MakeSweep("F0.01", SweepDirection::kUp)));
}

TEST(ParseSweepSelection, RejectsUnknownDirectionAndEmptyId) {
  SweepSelection selection;
  std::string error;
  EXPECT_FALSE(ParseSweepSelection("F1/left", &selection, &error));
  EXPECT_NE(error.find("'F1/up' or 'F1/down'"), std::string::npos) << error;
  EXPECT_FALSE(ParseSweepSelection("/up", &selection, &error));
  EXPECT_NE(error.find("no sweep id"), std::string::npos) << error;
}

TEST(SweepSelectionOverlaps, OnlyWhenSomeSweepIsSelectedByBoth) {
  EXPECT_TRUE(Parsed("F1").Overlaps(Parsed("F1")));
  EXPECT_TRUE(Parsed("F1").Overlaps(Parsed("F1/up")));
  EXPECT_TRUE(Parsed("F1/down").Overlaps(Parsed("F1")));
  EXPECT_FALSE(Parsed("F1/up").Overlaps(Parsed("F1/down")));
  EXPECT_FALSE(Parsed("F1").Overlaps(Parsed("F2")));
}

}  // namespace
}  // namespace dwellfit
