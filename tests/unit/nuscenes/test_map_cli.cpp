// `nsgraph inspect centerlines` on the fixture map: exit codes, JSON shape, poses equal to
// the library's bit for bit (shortest round-trip printing), edges, bad input.
#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "nsg/nuscenes/map_expansion.h"
#include "test_map_fixture.h"

namespace nsg::nuscenes {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

class CenterlinesCli : public ::testing::Test {
 protected:
  void SetUp() override { test::write_map(root_, test::small_map_text()); }
  test::CommandResult run(std::vector<std::string> extra) {
    std::vector<std::string> args{"inspect",    "centerlines",   "--dataroot", root_.path().string(),
                                  "--location", "boston-seaport"};
    args.insert(args.end(), extra.begin(), extra.end());
    return test::run_nsgraph(args);
  }
  test::TempDir root_{"map-cli"};
};

// Every printed pose parses back to exactly the library's double.
void expect_same_poses(const nlohmann::json& printed, const std::vector<geometry::Pose2>& poses) {
  ASSERT_EQ(printed.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    const double want[3] = {poses[i].x, poses[i].y, poses[i].yaw};
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(same_bits(printed[i][k].get<double>(), want[k]))
          << "pose " << i << " component " << k << ": " << printed[i][k] << " vs " << want[k];
    }
  }
}

TEST_F(CenterlinesCli, AllCenterlinesAndEdges) {
  const test::CommandResult r = run({});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const MapExpansion map = load_map_expansion(root_.path(), "boston-seaport");
  const auto expected = map.discretize_centerlines(2.0);
  ASSERT_EQ(j["centerlines"].size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    const auto& c = j["centerlines"][i];
    EXPECT_EQ(c["token"], expected[i].token);
    EXPECT_EQ(c["layer"], i < 2 ? "lane" : "lane_connector");
    expect_same_poses(c["poses"], expected[i].poses);
  }
  EXPECT_EQ(j["centerlines"][0]["poses"].size(), 16u);
  EXPECT_TRUE(j["centerlines"][3]["poses"].empty());  // conn-2: no arcline path
  EXPECT_EQ(j["edges"], nlohmann::json::parse(R"([["lane-a", "conn-1"], ["conn-1", "lane-b"]])"));
  // Shortest round-trip text: the π yaw of lane-b is printed as Python's repr would.
  EXPECT_NE(r.out.find("3.141592653589793"), std::string::npos);
}

TEST_F(CenterlinesCli, ResolutionAndTokenFilter) {
  const test::CommandResult r = run({"--resolution", "0.5", "--tokens", "conn-1,lane-a"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["centerlines"].size(), 2u);
  EXPECT_EQ(j["centerlines"][0]["token"], "lane-a");  // file order: lanes, then connectors
  EXPECT_EQ(j["centerlines"][1]["token"], "conn-1");
  const MapExpansion map = load_map_expansion(root_.path(), "boston-seaport");
  expect_same_poses(j["centerlines"][0]["poses"], map.discretize_lane("lane-a", 0.5));
  expect_same_poses(j["centerlines"][1]["poses"], map.discretize_lane("conn-1", 0.5));
  EXPECT_EQ(j["centerlines"][1]["poses"].size(), 14u);
  EXPECT_EQ(j["edges"], nlohmann::json::parse(R"([["lane-a", "conn-1"], ["conn-1", "lane-b"]])"));
}

TEST_F(CenterlinesCli, UnknownTokenExitsTwoNamingIt) {
  const test::CommandResult r = run({"--tokens", "lane-a,rb-1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("rb-1"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST_F(CenterlinesCli, BadOptionsExitTwo) {
  EXPECT_EQ(run({"--resolution", "0"}).exit_code, 2);
  EXPECT_EQ(run({"--resolution", "-1"}).exit_code, 2);
  const test::CommandResult r =
      test::run_nsgraph({"inspect", "centerlines", "--dataroot", root_.path().string(), "--location", "mars"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("mars"), std::string::npos) << r.err;
}

TEST_F(CenterlinesCli, BadMapExitsTwoNamingFile) {
  test::write_map(root_, test::replace_once(test::small_map_text(), "\"1.3\"", "\"1.2\""));
  const test::CommandResult old = run({});
  EXPECT_EQ(old.exit_code, 2);
  EXPECT_NE(old.err.find("maps/expansion/boston-seaport.json"), std::string::npos) << old.err;
  test::write_map(
      root_, test::replace_after(test::small_map_text(), "\"token\": \"lane-a\"", "\"poly-lane-a\"", "\"poly-none\""));
  const test::CommandResult dangling = run({});
  EXPECT_EQ(dangling.exit_code, 2);
  EXPECT_NE(dangling.err.find("boston-seaport.json"), std::string::npos) << dangling.err;
  EXPECT_NE(dangling.err.find("lane 'lane-a'"), std::string::npos) << dangling.err;
  const test::CommandResult missing = test::run_nsgraph(
      {"inspect", "centerlines", "--dataroot", (root_ / "nothing").string(), "--location", "singapore-onenorth"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("singapore-onenorth.json"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace nsg::nuscenes
