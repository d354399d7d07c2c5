// Runs the real nsgraph binary and checks exit codes and messages (docs/architecture.md).
#include <gtest/gtest.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "nsg/core/version.h"
#include "test_support.h"

namespace nsg {
namespace fs = std::filesystem;

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

TEST(Cli, NoCommandIsAUsageErrorListingTheCommands) {
  const test::CommandResult r = test::run_nsgraph({});
  EXPECT_EQ(r.exit_code, 2);
  for (const char* command : {"generate", "score", "frames", "train", "predict"})
    EXPECT_NE(r.err.find(std::string("  ") + command), std::string::npos) << command << " not listed:\n" << r.err;
  EXPECT_NE(r.err.find("no command given"), std::string::npos) << r.err;
}

// The common first mistakes get the problem first, for the right argument, and no parser
// library text.
TEST(Cli, CommonMistakesAreNamedProblemFirst) {
  test::TempDir tmp("mistakes");
  const std::string pred = (test::data_dir() / "golden/metrics/pred.json").string();
  const test::CommandResult gt =
      test::run_nsgraph({"score", "--ground-truth", (tmp / "nope").string(), "--submission", pred});
  EXPECT_EQ(gt.exit_code, 2);
  EXPECT_NE(gt.err.find("cannot open the ground truth: no such file"), std::string::npos) << gt.err;
  fs::create_directories(tmp / "folder");
  const std::string truth = (test::data_dir() / "golden/metrics/gt.json").string();
  const test::CommandResult dir =
      test::run_nsgraph({"score", "--ground-truth", truth, "--submission", (tmp / "folder").string()});
  EXPECT_EQ(dir.exit_code, 2);
  EXPECT_NE(dir.err.find("is a directory, not a submission"), std::string::npos) << dir.err;
  test::write_text(tmp / "empty.json", "");
  const test::CommandResult empty =
      test::run_nsgraph({"score", "--ground-truth", truth, "--submission", (tmp / "empty.json").string()});
  EXPECT_EQ(empty.exit_code, 1);
  EXPECT_NE(empty.err.find("got an empty file (0 bytes)"), std::string::npos) << empty.err;
  test::write_text(tmp / "cut.json", "{\"tiles\": ");
  const test::CommandResult cut =
      test::run_nsgraph({"score", "--ground-truth", truth, "--submission", (tmp / "cut.json").string()});
  EXPECT_EQ(cut.exit_code, 1);
  EXPECT_EQ(cut.err.find("json.exception"), std::string::npos) << cut.err;
}

}  // namespace nsg

namespace nsg {

// A flag that stands for a config key says what giving it does, with the key's type, range
// and default (it said "Colour the kept LiDAR points" for --no-rgb, and TEXT for numbers).
TEST(Cli, ConfigFlagsSayWhatTheyDoWithTypeAndDefault) {
  const auto r = test::run_nsgraph({"generate", "--help"});
  ASSERT_EQ(r.exit_code, 0);
  const auto line = [&](const std::string& flag) {
    const size_t at = r.out.find("  " + flag + " ");
    return at == std::string::npos ? std::string() : r.out.substr(at, r.out.find('\n', at) - at);
  };
  EXPECT_NE(line("--no-rgb").find("Sets config camera.rgb to false (default true)"), std::string::npos)
      << line("--no-rgb");
  EXPECT_NE(line("--no-semantic").find("to false"), std::string::npos) << line("--no-semantic");
  EXPECT_NE(line("--min-coverage").find("NUMBER"), std::string::npos) << line("--min-coverage");
  EXPECT_NE(line("--min-coverage").find("default "), std::string::npos) << line("--min-coverage");
  EXPECT_NE(line("--tiles-per-shard").find("INTEGER"), std::string::npos) << line("--tiles-per-shard");
  EXPECT_EQ(line("--min-coverage").find("TEXT"), std::string::npos) << line("--min-coverage");
}

}  // namespace nsg

namespace nsg {

// A mistyped option gets the name it was probably meant to be, before any complaint about
// required options (CLI11 said "The following arguments were not expected: 2 --thread",
// and only once every required option was given).
TEST(Cli, AMistypedOptionGetsDidYouMean) {
  const auto r = test::run_nsgraph({"score", "--thread", "2", "--submission", "s.json"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("score: unknown option '--thread' (did you mean '--threads'?)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Run 'nsgraph score --help'"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("not expected"), std::string::npos) << r.err;
  // Inside a command group, with `=`, and a global flag after the command is known.
  const auto sub = test::run_nsgraph({"inspect", "graph", "--dataroot=x", "--quiet", "--lcation=boston"});
  EXPECT_EQ(sub.exit_code, 2);
  EXPECT_NE(sub.err.find("inspect graph: unknown option '--lcation' (did you mean '--location'?)"), std::string::npos)
      << sub.err;
  // Nothing close: no suggestion, still the command named.
  const auto far = test::run_nsgraph({"stats", "ds", "--zzzzzzzz"});
  EXPECT_EQ(far.exit_code, 2);
  EXPECT_NE(far.err.find("stats: unknown option '--zzzzzzzz'\n"), std::string::npos) << far.err;
}

}  // namespace nsg

namespace nsg {

// What a release holds, listed as the devkit's list_scenes / list_samples do: the scene
// names export-cloud takes and the sample_data tokens inspect sweep takes (the README had
// `<sample_data token>` with no way to list them). On the real key frame.
TEST(Cli, InspectScenesAndSamplesListWhatTheReleaseHolds) {
  const std::string root = (test::data_dir() / "real/scene-0061-keyframe").string();
  const auto scenes = test::run_nsgraph({"inspect", "scenes", "--dataroot", root});
  ASSERT_EQ(scenes.exit_code, 0) << scenes.err;
  const nlohmann::json s = nlohmann::json::parse(scenes.out);
  ASSERT_EQ(s["scenes"].size(), 1u);
  EXPECT_EQ(s["scenes"][0]["name"], "scene-0061");
  EXPECT_EQ(s["scenes"][0]["location"], "singapore-onenorth");
  EXPECT_EQ(s["scenes"][0]["samples"], 1);
  const auto samples = test::run_nsgraph({"inspect", "samples", "--dataroot", root, "--scene", "scene-0061"});
  ASSERT_EQ(samples.exit_code, 0) << samples.err;
  const nlohmann::json list = nlohmann::json::parse(samples.out)["samples"];
  ASSERT_EQ(list.size(), 1u);
  const nlohmann::json& data = list[0]["sample_data"];
  for (const char* channel : {"LIDAR_TOP", "CAM_FRONT", "CAM_BACK_LEFT"})
    EXPECT_TRUE(data.contains(channel)) << channel << " " << data.dump();
  // The listed LiDAR token is one inspect sweep reads: the real sweep's 34 688 points.
  const auto sweep = test::run_nsgraph(
      {"inspect", "sweep", "--dataroot", root, "--token", data["LIDAR_TOP"].get<std::string>(), "--head", "1"});
  ASSERT_EQ(sweep.exit_code, 0) << sweep.err;
  EXPECT_EQ(nlohmann::json::parse(sweep.out)["total"], 34688);
  const auto unknown = test::run_nsgraph({"inspect", "samples", "--dataroot", root, "--scene", "scene-9999"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("scene-0061"), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("nsgraph inspect scenes"), std::string::npos) << unknown.err;
}

}  // namespace nsg
