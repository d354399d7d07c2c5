// The frame's ground truth on hand-made graphs where the answer is known: exact cuts at
// the window's edge, the ego's rotation, pieces of a lane that leaves and comes back, and
// successor links only between pieces that keep their lane's end and start.
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/frames/frame_lanes.h"
#include "nsg/geometry/transform.h"
#include "nsg/graph/from_map.h"
#include "nsg/nuscenes/map_expansion.h"
#include "test_support.h"

namespace nsg::frames {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A graph of polylines (global x, y), each its own lane; `successors[i]` lists lane indices.
struct GraphBuilder {
  graph::LaneGraph g;
  int32_t lane(const std::vector<std::pair<double, double>>& points, bool connector = false) {
    graph::Lane l;
    l.token = "lane-" + std::to_string(g.lanes.size());
    l.is_connector = connector;
    for (const auto& [x, y] : points) {
      l.nodes.push_back(static_cast<int32_t>(g.nodes.size()));
      g.nodes.push_back({x, y});
    }
    const int32_t index = static_cast<int32_t>(g.lanes.size());
    for (size_t i = 1; i < l.nodes.size(); ++i) g.edges.push_back({l.nodes[i - 1], l.nodes[i], index});
    g.lanes.push_back(l);
    return index;
  }
  // B starts where A ends: one shared node, as build_lane_graph joins them.
  void link(int32_t a, int32_t b) { g.lanes[static_cast<size_t>(a)].successors.push_back(b); }
};

// Ego at (x, y) with heading `yaw` (rad), level.
geometry::Rigid3 ego_at(double x, double y, double yaw) {
  return geometry::Rigid3::from_pose({x, y, 0.0}, geometry::quaternion_from_yaw(yaw));
}

FrameLanes cut(const graph::LaneGraph& g, const geometry::Rigid3& pose, int points = 11) {
  const graph::SegmentIndex index(g);
  return cut_frame_lanes(g, index, pose, WindowM{}, points);
}

void expect_point(const Eigen::Vector3d& p, double x, double y) {
  EXPECT_NEAR(p.x(), x, 1e-9);
  EXPECT_NEAR(p.y(), y, 1e-9);
  EXPECT_NEAR(p.z(), 0.0, 1e-9);
}

TEST(FrameLanes, AStraightLaneIsCutExactlyAtTheWindowAndResampledEvenly) {
  GraphBuilder b;
  std::vector<std::pair<double, double>> points;
  for (double x = 900.0; x <= 1100.0; x += 2.0) points.emplace_back(x, 500.0);
  b.lane(points);
  const FrameLanes f = cut(b.g, ego_at(1000.0, 500.0, 0.0));
  ASSERT_EQ(f.centerlines.size(), 1u);
  const FrameCenterline& c = f.centerlines[0];
  EXPECT_FALSE(c.starts_at_lane_start);
  EXPECT_FALSE(c.ends_at_lane_end);
  EXPECT_EQ(c.lane_token, "lane-0");
  EXPECT_EQ(c.id, 0);
  // The graph's nodes −50, −48, …, 50 (51 of them, the two ends on the border).
  ASSERT_EQ(c.points_2m.size(), 51u);
  expect_point(c.points_2m.front(), -50.0, 0.0);
  expect_point(c.points_2m.back(), 50.0, 0.0);
  ASSERT_EQ(c.points.size(), 11u);
  for (int k = 0; k < 11; ++k) expect_point(c.points[static_cast<size_t>(k)], -50.0 + 10.0 * k, 0.0);
  EXPECT_TRUE(f.successors.empty());
}

TEST(FrameLanes, TheEgosHeadingTurnsTheMapIntoItsFrame) {
  // Heading north (yaw 90°): a lane running north along the ego's track is straight ahead;
  // one running east 10 m north of the ego crosses the window from right (y < 0) to left.
  GraphBuilder b;
  b.lane({{0.0, -100.0}, {0.0, 100.0}});
  b.lane({{-100.0, 10.0}, {-7.0, 10.0}, {100.0, 10.0}});
  const FrameLanes f = cut(b.g, ego_at(0.0, 0.0, kPi / 2));
  ASSERT_EQ(f.centerlines.size(), 2u);
  expect_point(f.centerlines[0].points_2m.front(), -50.0, 0.0);
  expect_point(f.centerlines[0].points_2m.back(), 50.0, 0.0);
  // Global (x, 10) is ego (10, −x): the east-bound lane goes from y = 25 (x = −25) to y = −25.
  const FrameCenterline& east = f.centerlines[1];
  ASSERT_EQ(east.points_2m.size(), 3u);
  expect_point(east.points_2m[0], 10.0, 25.0);
  expect_point(east.points_2m[1], 10.0, 7.0);
  expect_point(east.points_2m[2], 10.0, -25.0);
}

TEST(FrameLanes, ALaneThatLeavesAndComesBackGivesTwoPiecesWithoutALink) {
  // A U: in at x = −30 going north, out through y = 25, back in, down to y = 0 at x = 30.
  GraphBuilder b;
  b.lane({{-30.0, 0.0}, {-30.0, 40.0}, {30.0, 40.0}, {30.0, 0.0}});
  const FrameLanes f = cut(b.g, ego_at(0.0, 0.0, 0.0));
  ASSERT_EQ(f.centerlines.size(), 2u);
  EXPECT_EQ(f.centerlines[0].id, 0);
  EXPECT_EQ(f.centerlines[1].id, 1);
  EXPECT_TRUE(f.centerlines[0].starts_at_lane_start);
  EXPECT_FALSE(f.centerlines[0].ends_at_lane_end);
  EXPECT_FALSE(f.centerlines[1].starts_at_lane_start);
  EXPECT_TRUE(f.centerlines[1].ends_at_lane_end);
  expect_point(f.centerlines[0].points_2m.back(), -30.0, 25.0);
  expect_point(f.centerlines[1].points_2m.front(), 30.0, 25.0);
  EXPECT_TRUE(f.successors.empty());
}

TEST(FrameLanes, SuccessorsLinkOnlyPiecesThatKeepTheirEndAndStart) {
  GraphBuilder b;
  const int32_t a = b.lane({{-40.0, 0.0}, {-10.0, 0.0}});
  const int32_t c = b.lane({{-10.0, 0.0}, {0.0, 10.0}}, /*connector=*/true);
  const int32_t d = b.lane({{0.0, 10.0}, {0.0, 60.0}});     // leaves the window: its end is cut
  const int32_t e = b.lane({{0.0, 60.0}, {30.0, 60.0}});    // wholly outside
  const int32_t far = b.lane({{80.0, 0.0}, {120.0, 0.0}});  // outside, a successor of nothing inside
  b.link(a, c);
  b.link(c, d);
  b.link(d, e);
  b.link(e, far);
  const FrameLanes f = cut(b.g, ego_at(0.0, 0.0, 0.0));
  ASSERT_EQ(f.centerlines.size(), 3u);  // a, c, d
  EXPECT_TRUE(f.centerlines[1].is_connector);
  EXPECT_FALSE(f.centerlines[2].ends_at_lane_end);
  const std::vector<std::pair<int32_t, int32_t>> want = {{0, 1}, {1, 2}};
  EXPECT_EQ(f.successors, want);
}

TEST(FrameLanes, ALaneOnlyTouchingTheBorderGivesNoCenterline) {
  GraphBuilder b;
  b.lane({{-60.0, 25.0}, {60.0, 25.0}});               // along the left edge: inside the closed box
  b.lane({{50.0, 30.0}, {50.0, 25.0}, {60.0, 25.0}});  // touches the corner only
  const FrameLanes f = cut(b.g, ego_at(0.0, 0.0, 0.0));
  ASSERT_EQ(f.centerlines.size(), 1u);
  EXPECT_EQ(f.centerlines[0].lane, 0);
}

TEST(FrameLanes, ResamplingByCountFollowsTheArcLength) {
  // An L of length 20: 5 points at 0, 5, 10 (the corner), 15, 20.
  const std::vector<Eigen::Vector3d> l = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}};
  const std::vector<Eigen::Vector3d> r = resample_by_count(l, 5);
  ASSERT_EQ(r.size(), 5u);
  expect_point(r[1], 5.0, 0.0);
  expect_point(r[2], 10.0, 0.0);
  expect_point(r[3], 10.0, 5.0);
  expect_point(r[4], 10.0, 10.0);
}

TEST(FrameLanes, WindowCornersFollowThePose) {
  const std::vector<Eigen::Vector2d> c = window_corners_global(ego_at(100.0, 200.0, kPi / 2), WindowM{});
  ASSERT_EQ(c.size(), 4u);
  // Ego (−50, −25) → global (100 + 25, 200 − 50).
  EXPECT_NEAR(c[0].x(), 125.0, 1e-9);
  EXPECT_NEAR(c[0].y(), 150.0, 1e-9);
  EXPECT_NEAR(c[2].x(), 75.0, 1e-9);
  EXPECT_NEAR(c[2].y(), 250.0, 1e-9);
}

}  // namespace
}  // namespace nsg::frames

namespace nsg::frames {
namespace {

// The hand-made map of tests/data/map/small-map.json: lane-a east along y = 12 from x = 10
// to 40, conn-1 a U-turn of radius 2 onto lane-b, west along y = 16 back to x = 10.
TEST(FrameLanesOnAMap, TheSmallMapsLanesAndConnectorAreCutAndLinkedAsDrawn) {
  const nuscenes::MapExpansion map =
      nuscenes::load_map_expansion_file(test::source_dir() / "tests/data/map/small-map.json");
  Issues issues;
  const graph::LaneGraph g = graph::build_lane_graph(map, graph::LaneGraphOptions{}, &issues);
  const graph::SegmentIndex index(g);
  const geometry::Rigid3 ego = geometry::Rigid3::from_pose({25.0, 14.0, 0.0}, geometry::Quaternion{});
  // A window holding everything: three whole centerlines, a → conn-1 → b linked.
  const FrameLanes all = cut_frame_lanes(g, index, ego, WindowM{-20, 20, -10, 10}, 11);
  ASSERT_EQ(all.centerlines.size(), 3u);
  std::vector<std::string> tokens;
  for (const FrameCenterline& c : all.centerlines) {
    tokens.push_back(c.lane_token);
    EXPECT_TRUE(c.starts_at_lane_start && c.ends_at_lane_end) << c.lane_token;
  }
  EXPECT_EQ(tokens, (std::vector<std::string>{"lane-a", "lane-b", "conn-1"}));
  EXPECT_TRUE(all.centerlines[2].is_connector);
  const std::vector<std::pair<int32_t, int32_t>> links = {{0, 2}, {2, 1}};
  EXPECT_EQ(all.successors, links);
  expect_point(all.centerlines[0].points.front(), -15.0, -2.0);
  expect_point(all.centerlines[0].points.back(), 15.0, -2.0);
  expect_point(all.centerlines[1].points.back(), -15.0, 2.0);
  // The U-turn's farthest point is 2 m beyond x = 40: ego x = 17.
  double far = 0.0;
  for (const Eigen::Vector3d& p : all.centerlines[2].points_2m) far = std::max(far, p.x());
  EXPECT_NEAR(far, 17.0, 0.02);
  // A narrower window cuts both lanes at x = ±10 and leaves the connector out: no links.
  const FrameLanes cut = cut_frame_lanes(g, index, ego, WindowM{-10, 10, -5, 5}, 11);
  ASSERT_EQ(cut.centerlines.size(), 2u);
  EXPECT_FALSE(cut.centerlines[0].starts_at_lane_start || cut.centerlines[0].ends_at_lane_end);
  expect_point(cut.centerlines[0].points.front(), -10.0, -2.0);
  expect_point(cut.centerlines[0].points.back(), 10.0, -2.0);
  expect_point(cut.centerlines[1].points.front(), 10.0, 2.0);
  EXPECT_TRUE(cut.successors.empty());
}

}  // namespace
}  // namespace nsg::frames
