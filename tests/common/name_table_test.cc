#include "dwellfit/estimator/common/name_table.h"

#include <gtest/gtest.h>

#include <string>

#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/analysis/profile_likelihood.h"
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

// `name` reads back as `expected` and is `expected`'s name.
template <typename Enum>
void ExpectBothWays(const char* (*name_of)(Enum), bool (*from_name)(const std::string&, Enum*),
                    const char* name, Enum expected) {
  EXPECT_STREQ(name_of(expected), name);
  Enum value = static_cast<Enum>(99);  // no enumerator
  EXPECT_TRUE(from_name(name, &value)) << name;
  EXPECT_EQ(value, expected) << name;
}

// The words of the config files and CSV columns, as docs/ spells them.
TEST(NameTableTest, TheLibrarysEnumsKeepTheirDocumentedNames) {
  ExpectBothWays(ExcitationName, ExcitationFromName, "base_displacement",
                 Excitation::kBaseDisplacement);
  ExpectBothWays(ExcitationName, ExcitationFromName, "force", Excitation::kForce);
  ExpectBothWays(ResponseName, ResponseFromName, "velocity", Response::kVelocity);
  ExpectBothWays(SweepDirectionName, SweepDirectionFromName, "down", SweepDirection::kDown);
  ExpectBothWays(HeldOutDwellsName, HeldOutDwellsFromName, "before_jump",
                 HeldOutDwells::kBeforeJump);
  ExpectBothWays(JumpTargetName, JumpTargetFromName, "amplitude_jump_down",
                 JumpTarget::kAmplitudeJumpDown);
  ExpectBothWays(IntervalMethodName, ParseIntervalMethod, "linearised",
                 IntervalMethod::kLinearised);
  EXPECT_STREQ(FitStatusName(FitStatus::kUnidentifiable), "unidentifiable");
  EXPECT_STREQ(ProfileEndName(ProfileEnd::kOpen), "open");
  Response response = Response::kDisplacement;
  EXPECT_FALSE(ResponseFromName("jerk", &response));
  EXPECT_EQ(response, Response::kDisplacement);
}

}  // namespace
}  // namespace dwellfit
