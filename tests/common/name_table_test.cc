#include "dwellfit/estimator/common/name_table.h"

#include <gtest/gtest.h>

#include "dwellfit/estimator/data/measured_quantity.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/forcing_calibration.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/staged_solve.h"

namespace dwellfit {
namespace {

enum class Colour { kRed, kGreen, kBlue };
constexpr const char* kColourNames[] = {"red", "green", "blue"};

TEST(NameTableTest, LooksUpBothWaysAndLeavesTheValueAloneOnAnUnknownName) {
  EXPECT_STREQ(NameOf(kColourNames, Colour::kGreen), "green");
  Colour colour = Colour::kRed;
  EXPECT_TRUE(FromName("blue", kColourNames, &colour));
  EXPECT_EQ(colour, Colour::kBlue);
  EXPECT_FALSE(FromName("Blue", kColourNames, &colour));  // names are case-sensitive
  EXPECT_FALSE(FromName("", kColourNames, &colour));
  EXPECT_EQ(colour, Colour::kBlue);
}

TEST(NameTableTest, AValueOutsideTheTableReadsAsAQuestionMark) {
  EXPECT_STREQ(NameOf(kColourNames, static_cast<Colour>(3)), "?");
  EXPECT_STREQ(NameOf(kColourNames, -1), "?");
}

// The words of the config files and CSV columns, as docs/ spells them.
TEST(NameTableTest, TheLibrarysEnumsKeepTheirDocumentedNames) {
  EXPECT_STREQ(ExcitationName(Excitation::kBaseDisplacement), "base_displacement");
  EXPECT_STREQ(ResponseName(Response::kAcceleration), "acceleration");
  EXPECT_STREQ(SweepDirectionName(SweepDirection::kDown), "down");
  EXPECT_STREQ(HeldOutDwellsName(HeldOutDwells::kBelowHalfPeak), "below_half_peak");
  EXPECT_STREQ(FitStatusName(FitStatus::kUnidentifiable), "unidentifiable");
  Excitation excitation = Excitation::kBaseAcceleration;
  EXPECT_TRUE(ExcitationFromName("force", &excitation));
  EXPECT_EQ(excitation, Excitation::kForce);
  Response response = Response::kDisplacement;
  EXPECT_TRUE(ResponseFromName("velocity", &response));
  EXPECT_EQ(response, Response::kVelocity);
  EXPECT_FALSE(ResponseFromName("jerk", &response));
  SweepDirection direction = SweepDirection::kUp;
  EXPECT_TRUE(SweepDirectionFromName("down", &direction));
  EXPECT_EQ(direction, SweepDirection::kDown);
  HeldOutDwells dwells = HeldOutDwells::kBelowHalfPeak;
  EXPECT_TRUE(HeldOutDwellsFromName("before_jump", &dwells));
  EXPECT_EQ(dwells, HeldOutDwells::kBeforeJump);
  JumpTarget target = JumpTarget::kFrequencyJumpUp;
  EXPECT_TRUE(JumpTargetFromName("amplitude_jump_down", &target));
  EXPECT_EQ(target, JumpTarget::kAmplitudeJumpDown);
}

}  // namespace
}  // namespace dwellfit
