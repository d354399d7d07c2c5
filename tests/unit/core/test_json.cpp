#include <gtest/gtest.h>

#include <string>

#include "nsg/core/error.h"
#include "nsg/core/json.h"

namespace nsg {

TEST(Json, ParsesOrdinaryDocuments) {
  const nlohmann::json j = parse_json_strict(R"({"a": [1, {"b": 2}], "c": {"a": 3}})", "doc.json");
  EXPECT_EQ(j["a"][1]["b"], 2);
  EXPECT_EQ(j["c"]["a"], 3);  // the same key in two objects is fine
}

TEST(Json, RefusesDuplicateKeysNamingTheKey) {
  try {
    parse_json_strict(R"({"schema_version":"2","schema_version":"1","tiles":{}})", "sub.json");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "sub.json");
    EXPECT_EQ(e.record(), "key \"schema_version\"");
    EXPECT_NE(e.expected().find("each key once"), std::string::npos);
  }
  EXPECT_THROW(parse_json_strict(R"({"tiles":{"k":{"nodes":[]},"k":{"nodes":[]}}})", "sub.json"), ParseError);
}

TEST(Json, RefusesDeepNestingWithoutRecursing) {
  // 30 000 nested arrays: a recursive reader or converter overflows the stack.
  const std::string deep = std::string(30000, '[') + std::string(30000, ']');
  try {
    parse_json_strict(deep, "meta.json");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.record(), "nesting depth 65");
  }
  const std::string ok = std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']');
  EXPECT_NO_THROW(parse_json_strict(ok, "meta.json"));
}

TEST(Json, InvalidJsonNamesTheByteAndStaysPrintable) {
  try {
    parse_json_strict("{\"a\": \"\xff\xfe\"}", "sub.json");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.record().rfind("byte ", 0), 0u);
    EXPECT_EQ(std::string(e.what()).find('\xff'), std::string::npos);
  }
}

TEST(Json, PrintableUtf8EscapesInvalidBytesOnly) {
  EXPECT_EQ(printable_utf8("caf\xc3\xa9"), "caf\xc3\xa9");
  EXPECT_EQ(printable_utf8("a\xff"
                           "b"),
            "a\\xFFb");
  EXPECT_EQ(printable_utf8("\xe2\x82"), "\\xE2\\x82");  // truncated sequence
}

}  // namespace nsg
