// Arcline discretization against the devkit: every golden case at every resolution must
// match bit for bit; plus analytic cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/geometry/arcline.h"
#include "test_support.h"

namespace nsg::geometry {
namespace {

constexpr double kPi = 3.141592653589793;

ArclinePath path_from_json(const nlohmann::json& j) {
  ArclinePath p;
  p.start_pose = {j["start_pose"][0], j["start_pose"][1], j["start_pose"][2]};
  p.end_pose = {j["end_pose"][0], j["end_pose"][1], j["end_pose"][2]};
  EXPECT_TRUE(parse_arcline_shape(j["shape"].get<std::string>(), &p.shape));
  p.radius_m = j["radius"];
  for (int i = 0; i < 3; ++i) p.segment_length_m[i] = j["segment_length"][i];
  return p;
}

ArclinePath straight_path(double length_m) {
  ArclinePath p;
  p.start_pose = {10.0, 20.0, 0.0};
  p.shape = ArclineShape::kLSL;
  p.radius_m = 999.999;
  p.segment_length_m = {0.0, length_m, 0.0};
  return p;
}

// Bitwise equality (also distinguishes +0.0 / -0.0).
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Arcline, GoldenDevkitCasesAreBitIdentical) {
  std::ifstream in(nsg::test::data_dir() / "golden" / "arcline-discretize.json");
  ASSERT_TRUE(in.good()) << "missing tests/data/golden/arcline-discretize.json";
  const nlohmann::json golden = nlohmann::json::parse(in);
  const auto& cases = golden.at("cases");
  ASSERT_GE(cases.size(), 100u);
  size_t compared = 0;
  for (size_t c = 0; c < cases.size(); ++c) {
    const ArclinePath path = path_from_json(cases[c].at("path"));
    for (const auto& [res_text, expected] : cases[c].at("discretized").items()) {
      const double resolution = std::stod(res_text);
      const std::vector<Pose2> poses = discretize_arcline(path, resolution);
      ASSERT_EQ(poses.size(), expected.size()) << "case " << c << " resolution " << res_text;
      for (size_t i = 0; i < poses.size(); ++i) {
        const double want[3] = {expected[i][0], expected[i][1], expected[i][2]};
        const double got[3] = {poses[i].x, poses[i].y, poses[i].yaw};
        for (int k = 0; k < 3; ++k) {
          if (!same_bits(got[k], want[k])) {
            char msg[256];
            std::snprintf(msg, sizeof msg, "case %zu (%s) resolution %s pose %zu component %d: got %.17g want %.17g", c,
                          std::string(arcline_shape_name(path.shape)).c_str(), res_text.c_str(), i, k, got[k], want[k]);
            FAIL() << msg;
          }
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 10000u);
}

TEST(Arcline, ZeroLengthGivesTwoIdenticalPoses) {
  ArclinePath p = straight_path(0.0);
  p.start_pose.yaw = 4.0;  // stored unwrapped: both poses carry the wrapped yaw
  const std::vector<Pose2> poses = discretize_arcline(p, 2.0);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0], poses[1]);
  EXPECT_DOUBLE_EQ(poses[0].x, 10.0);
  EXPECT_DOUBLE_EQ(poses[0].yaw, 4.0 - 2 * kPi);
}

TEST(Arcline, TwentyFiveMetresAtTwoGivesFourteenPoses) {
  ArclinePath p;
  p.start_pose = {0.0, 0.0, 0.0};
  p.shape = ArclineShape::kLSR;
  p.radius_m = 2.0;
  p.segment_length_m = {5.0, 15.0, 5.0};
  const std::vector<Pose2> poses = discretize_arcline(p, 2.0);
  EXPECT_EQ(poses.size(), 14u);
  // Left arc of 5 m at r = 2 turns +2.5 rad, the right arc turns it back: end yaw 0.
  EXPECT_NEAR(poses.back().yaw, 0.0, 1e-12);
  const Pose2 end = arcline_pose_at(p, p.length_m());
  EXPECT_NEAR(poses.back().x, end.x, 1e-9);
  EXPECT_NEAR(poses.back().y, end.y, 1e-9);
}

TEST(Arcline, StraightOnlyPathIsEvenlySpacedOnALine) {
  ArclinePath p = straight_path(25.0);
  p.start_pose.yaw = kPi / 2;  // heading north
  const std::vector<Pose2> poses = discretize_arcline(p, 2.0);
  ASSERT_EQ(poses.size(), 14u);
  const double spacing = 25.0 / 13.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(poses[i].x, 10.0, 1e-12);
    EXPECT_NEAR(poses[i].y, 20.0 + spacing * static_cast<double>(i), 1e-12);
    EXPECT_DOUBLE_EQ(poses[i].yaw, kPi / 2);
  }
}

TEST(Arcline, QuarterCircleEndsWhereGeometrySays) {
  ArclinePath p;
  p.shape = ArclineShape::kLSL;
  p.radius_m = 10.0;
  p.segment_length_m = {10.0 * kPi / 2, 0.0, 0.0};
  const std::vector<Pose2> poses = discretize_arcline(p, 1.0);
  EXPECT_EQ(poses.size(), 17u);  // ceil(15.708) + 1
  EXPECT_NEAR(poses.back().x, 10.0, 1e-9);
  EXPECT_NEAR(poses.back().y, 10.0, 1e-9);
  EXPECT_NEAR(poses.back().yaw, kPi / 2, 1e-12);
  for (const Pose2& q : poses) EXPECT_NEAR(std::hypot(q.x, q.y - 10.0), 10.0, 1e-9);
}

TEST(Arcline, LaneConcatenatesWithoutDeduplication) {
  const ArclinePath a = straight_path(4.0);
  ArclinePath b = straight_path(4.0);
  b.start_pose.x = 14.0;
  const std::vector<Pose2> lane = discretize_lane({a, b}, 2.0);
  ASSERT_EQ(lane.size(), 6u);
  EXPECT_EQ(lane[2], lane[3]);  // joint pose repeated like the devkit
  EXPECT_TRUE(discretize_lane({}, 2.0).empty());
}

TEST(Arcline, ShapesAndCurvatureSigns) {
  for (std::string_view name : {"LSL", "LSR", "RSL", "RSR", "LRL", "RLR"}) {
    ArclineShape s;
    ASSERT_TRUE(parse_arcline_shape(name, &s));
    EXPECT_EQ(arcline_shape_name(s), name);
  }
  ArclineShape s;
  EXPECT_FALSE(parse_arcline_shape("LLL", &s));
  EXPECT_FALSE(parse_arcline_shape("lsl", &s));
  ArclinePath p;
  p.radius_m = 4.0;
  p.shape = ArclineShape::kLRL;
  EXPECT_EQ(p.curvature(0), 0.25);
  EXPECT_EQ(p.curvature(1), -0.25);
  EXPECT_EQ(p.curvature(2), 0.25);
  p.shape = ArclineShape::kRSR;
  EXPECT_EQ(p.curvature(0), -0.25);
  EXPECT_EQ(p.curvature(1), 0.0);
  EXPECT_EQ(p.curvature(2), -0.25);
}

TEST(Arcline, WrapFollowsPythonFloorMod) {
  EXPECT_DOUBLE_EQ(wrap_angle_devkit(0.0), 0.0);
  EXPECT_DOUBLE_EQ(wrap_angle_devkit(kPi), -kPi);  // [−π, π)
  EXPECT_NEAR(wrap_angle_devkit(-kPi - 0.5), kPi - 0.5, 1e-15);
  EXPECT_NEAR(wrap_angle_devkit(7.0), 7.0 - 2 * kPi, 1e-15);
}

TEST(Arcline, BadResolutionIsAConfigError) {
  const ArclinePath p = straight_path(10.0);
  EXPECT_THROW(discretize_arcline(p, 0.0), nsg::ConfigError);
  EXPECT_THROW(discretize_arcline(p, -1.0), nsg::ConfigError);
  EXPECT_THROW(discretize_arcline(p, std::nan("")), nsg::ConfigError);
}

}  // namespace
}  // namespace nsg::geometry
