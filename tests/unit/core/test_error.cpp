#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/core/issues.h"

namespace nsg {

TEST(Error, MessageNamesFileRecordAndExpectation) {
  const DataError e("v1.0-mini/sample.json", "sample 0123", "field 'scene_token' names no scene");
  EXPECT_STREQ(e.what(), "v1.0-mini/sample.json: sample 0123: field 'scene_token' names no scene");
  EXPECT_EQ(e.file(), "v1.0-mini/sample.json");
  EXPECT_EQ(e.record(), "sample 0123");
  EXPECT_EQ(e.exit_code(), kExitInput);
}

TEST(Error, EmptyPartsAreLeftOut) {
  EXPECT_STREQ(IoError("a.bin", "", "missing").what(), "a.bin: missing");
  EXPECT_STREQ(ConfigError("", "", "bad").what(), "bad");
}

TEST(Error, InternalErrorExitsThree) { EXPECT_EQ(InternalError("", "", "x").exit_code(), kExitInternal); }

TEST(Error, CheckMacroThrowsTheNamedType) {
  EXPECT_NO_THROW(NSG_CHECK(true, ParseError, "f", "r", "m"));
  EXPECT_THROW(NSG_CHECK(1 == 2, ParseError, "f", "r", "m"), ParseError);
}

TEST(Issues, CountsFormatsAndThrowsInStrictMode) {
  Issues issues;
  issues.warning("graph.isolated", "lane-1", "no connectivity");
  EXPECT_NO_THROW(issues.throw_if_errors("map.json"));
  issues.error("graph.dangling", "lane-2", "outgoing names missing token x");
  EXPECT_EQ(issues.count(Severity::kError), 1u);
  EXPECT_EQ(issues.count(Severity::kWarning), 1u);
  EXPECT_EQ(issues.count_check("graph.dangling"), 1u);
  EXPECT_EQ(issues.format(),
            "warning graph.isolated lane-1: no connectivity\n"
            "error graph.dangling lane-2: outgoing names missing token x\n");
  try {
    issues.throw_if_errors("map.json");
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), "map.json");
    EXPECT_EQ(e.record(), "lane-2");
  }
}

}  // namespace nsg
