#include <gtest/gtest.h>

#include "nsg/core/strings.h"

namespace nsg {

TEST(Strings, SplitJoinTrim) {
  EXPECT_EQ(split("a,b,,c", ','), (std::vector<std::string>{"a", "b", "", "c"}));
  EXPECT_EQ(join({"a", "b"}, ", "), "a, b");
  EXPECT_EQ(trim("  x y \n"), "x y");
  EXPECT_TRUE(starts_with("graph.edge_length", "graph."));
  EXPECT_TRUE(ends_with("a.pcd.bin", ".pcd.bin"));
}

TEST(Strings, FormatDoubleIsShortestRoundTrip) {
  EXPECT_EQ(format_double(0.1), "0.1");
  EXPECT_EQ(format_double(2.0), "2.0");
  EXPECT_EQ(format_double(1179.4673290964536), "1179.4673290964536");
  EXPECT_EQ(format_double(1e-7), "1e-07");
  const double v = 2.739593514975998;
  EXPECT_EQ(std::stod(format_double(v)), v);
}

TEST(Strings, WildcardMatch) {
  EXPECT_TRUE(wildcard_match("graph.*", "graph.edge_length"));
  EXPECT_TRUE(wildcard_match("*.sha256", "shard.sha256"));
  EXPECT_TRUE(wildcard_match("raster.?ize", "raster.size"));
  EXPECT_FALSE(wildcard_match("graph.*", "raster.size"));
  EXPECT_TRUE(wildcard_match("*", ""));
}

}  // namespace nsg
