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

TEST(Json, BuildsTheSameDocumentAsNlohmann) {
  const std::string text =
      R"([{"a": [1, {"b": [], "c": {}}, -2, 3.5e2, 18446744073709551615], "d": null}, true, "s\u00e9", [[[]]], {}])";
  EXPECT_EQ(parse_json_strict(text, "doc.json"), nlohmann::json::parse(text));
  EXPECT_EQ(parse_json_strict("7", "doc.json"), nlohmann::json(7));
}

TEST(Json, NumberBeyondDoubleIsAParseErrorWithoutAByte) {
  try {
    parse_json_strict("[1e777]", "sub.json");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.record(), "");
    EXPECT_NE(e.expected().find("valid JSON"), std::string::npos);
  }
}

// Shapes that made the callback parser quadratic (300 000 empty objects took 36 s,
// 100 000 keys 84 s). A regression shows as ctest's timeout; the figures are in the note.
TEST(Json, ManySiblingsParseInOnePass) {
  std::string objects = "[";
  for (int k = 0; k < 300000; ++k) objects += k ? ",{}" : "{}";
  objects += "]";
  EXPECT_EQ(parse_json_strict(objects, "big.json").size(), 300000u);
  std::string keys = "{";
  for (int k = 0; k < 100000; ++k) keys += (k ? ",\"" : "\"") + std::to_string(k) + "\":{\"nodes\":[],\"edges\":[]}";
  keys += "}";
  const nlohmann::json doc = parse_json_strict(keys, "big.json");
  EXPECT_EQ(doc.size(), 100000u);
  EXPECT_TRUE(doc["99999"]["edges"].is_array());
}

TEST(Json, PrintableUtf8EscapesInvalidBytesOnly) {
  EXPECT_EQ(printable_utf8("caf\xc3\xa9"), "caf\xc3\xa9");
  EXPECT_EQ(printable_utf8("a\xff"
                           "b"),
            "a\\xFFb");
  EXPECT_EQ(printable_utf8("\xe2\x82"), "\\xE2\\x82");  // truncated sequence
}

}  // namespace nsg
