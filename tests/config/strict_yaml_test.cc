#include "dwellfit/config/strict_yaml.h"

#include <string>

#include "dwellfit/config/config_source.h"
#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

// StrictMap keeps each key's position after the iteration that read it. The
// key node must be held by value: yaml-cpp's iterators hand out their
// (key, value) pair as a temporary, and a reference into it dangles
// (stack-use-after-scope under AddressSanitizer).
TEST(StrictMap, KeepsEveryKeyAndItsLineAfterReading) {
  const ConfigSource source =
      ConfigSource::Parse("block.yaml", "first: 1\nsecond: two\nthird:\n  nested: 3\n");
  const StrictMap map(DocumentValue(source), source, {"first", "second", "third"});
  const auto first = map.Optional("first");
  const auto second = map.Optional("second");
  const auto third = map.Optional("third");
  ASSERT_TRUE(first && second && third);
  EXPECT_EQ(first->mark.line, 0);
  EXPECT_EQ(second->mark.line, 1);
  EXPECT_EQ(third->mark.line, 2);
  EXPECT_EQ(ReadInt(*first, source), 1);
  EXPECT_EQ(ReadNonEmptyString(*second, source), "two");
  EXPECT_EQ(third->path, "third");
}

TEST(StrictMap, AnUnknownKeyIsNamedWithItsLine) {
  const ConfigSource source = ConfigSource::Parse("block.yaml", "first: 1\nsecnd: 2\n");
  try {
    StrictMap map(DocumentValue(source), source, {"first", "second"});
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("block.yaml:2: field 'secnd'"));
    EXPECT_THAT(error.what(), HasSubstr("did you mean 'second'"));
  }
}

// YAML's "\0" escape would cut a path or a name short where the system or a
// printed config reads it.
TEST(ReadNonEmptyString, ANulCharacterIsAnError) {
  const ConfigSource source =
      ConfigSource::Parse("block.yaml", "path: \"out\\0put\"\nname: output\n");
  const StrictMap map(DocumentValue(source), source, {"path", "name"});
  EXPECT_EQ(ReadNonEmptyString(*map.Optional("name"), source), "output");
  try {
    ReadNonEmptyString(*map.Optional("path"), source);
    FAIL() << "a NUL character was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("block.yaml:1: field 'path': holds a NUL character"));
  }
}

// yaml-cpp 0.7's LoadAll never returns on a stray ',' or '}' at the top
// level (its parser yields empty documents without advancing): found by the
// dwell-plan fuzzer as a timeout. Parse bounds the walk and says what is wrong.
TEST(ConfigSourceParse, AStrayCommaOrBraceAtTheTopLevelIsASyntaxErrorNotAHang) {
  for (const char* text : {", a}\n", "#c\n, delta: 1}\nsweeps:\n  - {id: A40\n"}) {
    try {
      ConfigSource::Parse("stray.yaml", text);
      FAIL() << "accepted: " << text;
    } catch (const InputError& error) {
      EXPECT_THAT(error.what(), HasSubstr("stray.yaml: YAML syntax error: the reader does not get "
                                          "past a stray ','"));
    }
  }
}

TEST(ConfigSourceParse, ASecondDocumentWithContentIsNamedAtItsLine) {
  try {
    ConfigSource::Parse("two.yaml", "a: 1\n---\nb: 2\n");
    FAIL() << "a second document was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("two.yaml:3: a second YAML document starts here"));
  }
  EXPECT_TRUE(ConfigSource::Parse("one.yaml", "a: 1\n---\n").root().IsMap());
}

}  // namespace
}  // namespace dwellfit
