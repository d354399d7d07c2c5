#pragma once
// The hand-written map fixture (tests/data/map/small-map.json) placed in a fake dataroot
// as maps/expansion/boston-seaport.json, plus text-mutation helpers for malformed copies.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "test_support.h"

namespace nsg::test {

inline std::string small_map_text() { return read_text(source_dir() / "tests" / "data" / "map" / "small-map.json"); }

// Writes `text` as <root>/maps/expansion/<location>.json and returns that path.
inline std::filesystem::path write_map(const TempDir& root, const std::string& text,
                                       const std::string& location = "boston-seaport") {
  const std::filesystem::path file = root.path() / "maps" / "expansion" / (location + ".json");
  write_text(file, text);
  return file;
}

// `text` with the first occurrence of `from` replaced by `to` (the test fails if absent).
inline std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const size_t pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "fixture does not contain: " << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

// Replaces the first `from` that follows the first `anchor` (e.g. a field of one record).
inline std::string replace_after(std::string text, const std::string& anchor, const std::string& from,
                                 const std::string& to) {
  const size_t at = text.find(anchor);
  EXPECT_NE(at, std::string::npos) << "fixture does not contain: " << anchor;
  if (at == std::string::npos) return text;
  const size_t pos = text.find(from, at);
  EXPECT_NE(pos, std::string::npos) << "no " << from << " after " << anchor;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

}  // namespace nsg::test
