// Runs the real nsgraph binary and checks exit codes and messages (DESIGN.md §2).
#include <gtest/gtest.h>

#include "nsg/core/version.h"
#include "test_support.h"

namespace nsg {

TEST(Cli, VersionPrintsTheProjectVersion) {
  const auto r = test::run_nsgraph({"--version"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find(std::string("nsgraph ") + kVersion), std::string::npos) << r.out;
}

TEST(Cli, HelpListsCommandsAndExitsZero) {
  const auto r = test::run_nsgraph({"--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("inspect"), std::string::npos) << r.out;
}

TEST(Cli, UnknownCommandIsAUsageError) {
  const auto r = test::run_nsgraph({"frobnicate"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(r.err.empty());
}

TEST(Cli, NoCommandIsAUsageError) {
  EXPECT_EQ(test::run_nsgraph({}).exit_code, 2);
}

}  // namespace nsg
