// Runs the real nsgraph binary and checks exit codes and messages (docs/architecture.md).
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

// A misspelt command must not let a later word act as a global flag: `--version` here is
// the release option of the command the user meant, not the program's version flag.
TEST(Cli, UnknownCommandExitsTwoAndListsTheCommands) {
  const auto r = test::run_nsgraph({"generat", "--dataroot", "/nonexistent-nsg", "--version", "v1.0-mini"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out.find(kVersion), std::string::npos) << "no program version: " << r.out;
  EXPECT_NE(r.err.find("unknown command 'generat' (did you mean 'generate'?)"), std::string::npos) << r.err;
  for (const char* command : {"synth", "inspect", "generate", "merge", "validate", "score", "train", "predict"})
    EXPECT_NE(r.err.find(command), std::string::npos) << command << " not listed: " << r.err;
  const auto quiet = test::run_nsgraph({"-q", "frobnicate", "--version"});
  EXPECT_EQ(quiet.exit_code, 2);
  EXPECT_NE(quiet.err.find("unknown command 'frobnicate'"), std::string::npos) << quiet.err;
  EXPECT_EQ(quiet.err.find("did you mean"), std::string::npos) << "no suggestion for a distant word: " << quiet.err;
}

TEST(Cli, VersionAfterACommandIsTheCommandsOwnOption) {
  const auto r = test::run_nsgraph({"generate", "--version", "v1.0-mini", "--print-config"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"version\": \"v1.0-mini\""), std::string::npos) << r.out;
  const auto global = test::run_nsgraph({"-q", "--version"});
  EXPECT_EQ(global.exit_code, 0);
  EXPECT_NE(global.out.find(std::string("nsgraph ") + kVersion), std::string::npos) << global.out;
}

// A command that reads no release has no --version: the program's flag must not answer
// it (it printed the program version, exit 0, and wrote nothing).
TEST(Cli, VersionAfterACommandWithoutOneIsRefusedByName) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"score", "--ground-truth", "g.json", "--submission", "s.json", "--version", "v1.0-mini"},
           {"stats", "ds", "--version=v1.0-mini"},
           {"inspect", "graph", "--version", "v1.0-mini"}}) {
    const auto r = test::run_nsgraph(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(args[0] + (args[0] == "inspect" ? " graph" : "") + ": --version: this command reads no"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out.find(std::string("nsgraph ") + kVersion), std::string::npos) << r.out;
  }
}

TEST(Cli, NoCommandIsAUsageError) { EXPECT_EQ(test::run_nsgraph({}).exit_code, 2); }

}  // namespace nsg
