#include <gtest/gtest.h>

#include <algorithm>

#include "nsg/core/error.h"
#include "nsg/core/issues.h"
#include "nsg/core/strings.h"

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

TEST(Error, OutsideControlCharactersAreEscapedInMessagesNotInFields) {
  // A submission key with CR/LF, an ANSI colour and a NUL: the message stays one line.
  const std::string key = std::string("a\r\nscored 3 tiles APLS 1.0000\x1b[2K") + '\0' + "tail\xc2\x9b";
  const DataError e("sub.json", "/tiles/" + key, "a key");
  const std::string what = e.what();
  EXPECT_EQ(what.find_first_of("\r\n\x1b"), std::string::npos) << what;
  EXPECT_EQ(what.find('\0'), std::string::npos);
  EXPECT_NE(what.find("\\x0D\\x0Ascored 3 tiles APLS 1.0000\\x1B[2K\\x00tail\\u009B"), std::string::npos) << what;
  EXPECT_EQ(e.record(), "/tiles/" + key);  // the raw bytes for callers that need them
  Issues issues;
  issues.error("submission.key", key, "msg\rwith CR");
  EXPECT_EQ(issues.format().find('\r'), std::string::npos);
  const std::string formatted = issues.format();
  EXPECT_EQ(std::count(formatted.begin(), formatted.end(), '\n'), 1);
}

// Our own multi-line "expected" (a problem list) keeps its lines, each continuation
// indented: a value quoted in it cannot start a line that passes for a log line.
TEST(Error, ExpectedKeepsItsLinesIndented) {
  const DataError e("out", "merge", "every share finished:\n  share 1 of 3: missing\nscored 3 tiles\x1b[2K");
  EXPECT_EQ(std::string(e.what()),
            "out: merge: every share finished:\n  share 1 of 3: missing\n  scored 3 tiles\\x1B[2K");
}

TEST(Strings, PrintableTextEscapesControlsAndKeepsText) {
  EXPECT_EQ(printable_text("caf\xc3\xa9 \xe2\x86\x92 ok"), "caf\xc3\xa9 \xe2\x86\x92 ok");
  EXPECT_EQ(printable_text("a\tb\x7f"), "a\\x09b\\x7F");
  EXPECT_EQ(printable_text("two\nlines", true), "two\nlines");
  EXPECT_EQ(printable_text("two\nlines"), "two\\x0Alines");
  EXPECT_EQ(printable_text("\xff"), "\\xFF");
}

}  // namespace nsg
