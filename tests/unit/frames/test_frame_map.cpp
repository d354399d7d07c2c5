// Lane segments and areas of a frame (frame_map.h) on hand-made maps whose answers are known:
// lanelines cut from dividers or moved by the half width, line types by majority, crossings
// clipped to the window and closed, road-boundary rings cut into the stretches inside it.
#include <gtest/gtest.h>

#include <cmath>

#include "../nuscenes/real_defects_fixture.h"
#include "../nuscenes/test_map_fixture.h"
#include "nsg/frames/frame_map.h"
#include "nsg/graph/from_map.h"

namespace nsg::frames {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<Vector2d> line_x(double x0, double x1, double y, double step) {
  std::vector<Vector2d> out;
  for (double x = x0; x <= x1 + 1e-9; x += step) out.emplace_back(x, y);
  return out;
}

LaneBoundary boundary(const std::vector<Vector2d>& points, LineType first, LineType rest, double switch_at_x) {
  LaneBoundary b;
  b.points = points;
  for (size_t k = 0; k + 1 < points.size(); ++k) b.types.push_back(points[k].x() < switch_at_x ? first : rest);
  return b;
}

// The pieces of a global chain (ego at the origin, axes aligned: global = ego) in the window.
std::vector<FrameCenterline> pieces(const std::vector<Vector2d>& chain, const WindowM& w, int32_t lane,
                                    bool connector) {
  std::vector<Vector3d> c;
  for (const Vector2d& p : chain) c.emplace_back(p.x(), p.y(), 0.0);
  return clip_chain(c, w, lane, "lane-" + std::to_string(lane), connector);
}

void expect_near(const Vector3d& got, double x, double y, const std::string& what) {
  EXPECT_NEAR(got.x(), x, 1e-9) << what;
  EXPECT_NEAR(got.y(), y, 1e-9) << what;
}

TEST(FrameMap, NuScenesSegmentTypesBecomeOpenLaneV2LineTypes) {
  EXPECT_EQ(line_type_of("SINGLE_SOLID_WHITE"), LineType::kSolid);
  EXPECT_EQ(line_type_of("DOUBLE_SOLID_YELLOW"), LineType::kSolid);
  EXPECT_EQ(line_type_of("DOUBLE_DASHED_WHITE"), LineType::kDash);
  EXPECT_EQ(line_type_of("SOLID_DASHED_WHITE"), LineType::kSolid);  // not to be crossed from one side
  EXPECT_EQ(line_type_of("NIL"), LineType::kNone);
  EXPECT_EQ(line_type_of(""), LineType::kNone);
}

TEST(FrameMap, LanelinesAreTheDividersCutToThePieceOrTheHalfWidthMoved) {
  const WindowM window;  // x ±50, y ±25
  // Lane 0 along +x from x = -100 to 100 at y = 0; its left divider at y = 1.6 is solid up to
  // x = 20 (70 of the 100 m inside) and dashed after; its right divider at y = -1.6, dashed.
  // Lane 1: a connector from (100, 0) turning to +y; no dividers, half width 1.4 m.
  LocationMapElements map;
  map.left = {boundary(line_x(-100, 100, 1.6, 5), LineType::kSolid, LineType::kDash, 20), LaneBoundary{}};
  map.right = {boundary(line_x(-100, 100, -1.6, 5), LineType::kDash, LineType::kDash, 0), LaneBoundary{}};
  map.half_width_m = {1.6, 1.4};
  FrameLanes lanes;
  for (FrameCenterline& c : pieces(line_x(-100, 100, 0.0, 2), window, 0, false)) lanes.centerlines.push_back(c);
  for (FrameCenterline& c : pieces({{40, -10}, {40, 0}, {40, 10}}, window, 1, true)) lanes.centerlines.push_back(c);
  ASSERT_EQ(lanes.centerlines.size(), 2u);

  const FrameMapElements got = cut_frame_map(lanes, map, geometry::Rigid3{}, window, 10);
  ASSERT_EQ(got.lane_segments.size(), 2u);
  const FrameLaneSegment& lane = got.lane_segments[0];
  EXPECT_EQ(lane.id, lanes.centerlines[0].id);
  ASSERT_EQ(lane.centerline.size(), 10u);
  ASSERT_EQ(lane.left_laneline.size(), 10u);
  expect_near(lane.centerline.front(), -50, 0, "centerline start (the window's edge)");
  expect_near(lane.centerline.back(), 50, 0, "centerline end");
  // The divider cut where the piece's ends project onto it: x -50 … 50.
  expect_near(lane.left_laneline.front(), -50, 1.6, "left start");
  expect_near(lane.left_laneline.back(), 50, 1.6, "left end");
  expect_near(lane.right_laneline.front(), -50, -1.6, "right start");
  expect_near(lane.left_laneline[3], -50 + 100.0 * 3 / 9, 1.6, "evenly spaced");
  EXPECT_EQ(lane.left_type, LineType::kSolid);  // 70 m solid, 30 m dash
  EXPECT_EQ(lane.right_type, LineType::kDash);
  EXPECT_FALSE(lane.left_from_offset);
  EXPECT_FALSE(lane.is_intersection_or_connector);

  const FrameLaneSegment& connector = got.lane_segments[1];
  EXPECT_TRUE(connector.is_intersection_or_connector);
  EXPECT_TRUE(connector.left_from_offset);
  EXPECT_TRUE(connector.right_from_offset);
  EXPECT_EQ(connector.left_type, LineType::kNone);
  // Heading +y: left is −x.
  expect_near(connector.left_laneline.front(), 40 - 1.4, -10, "connector left");
  expect_near(connector.right_laneline.back(), 40 + 1.4, 10, "connector right");
}

TEST(FrameMap, ACrossingIsClippedToTheWindowAndClosed) {
  WindowM window;
  LocationMapElements map;
  // A 10 × 6 m crossing whose east half lies beyond x = 50; another far away.
  map.ped_crossings = {{{45, -3}, {55, -3}, {55, 3}, {45, 3}}, {{300, 300}, {310, 300}, {310, 310}}};
  const FrameMapElements got = cut_frame_map({}, map, geometry::Rigid3{}, window, 10);
  ASSERT_EQ(got.areas.size(), 1u);
  const FrameArea& a = got.areas[0];
  EXPECT_EQ(a.category, AreaCategory::kPedestrianCrossing);
  EXPECT_EQ(a.id, 0);
  ASSERT_EQ(a.points.size(), 5u);  // four corners, closed
  EXPECT_EQ(a.points.front(), a.points.back());
  double x_max = -1e9;
  for (const Vector3d& p : a.points) x_max = std::max(x_max, p.x());
  EXPECT_EQ(x_max, 50.0);
  EXPECT_TRUE(clip_polygon_to_window({{100, 100}, {110, 100}, {110, 110}}, window).empty());
}

TEST(FrameMap, RoadBoundaryRingsAreCutIntoTheStretchesInsideTheWindow) {
  WindowM window;
  // A 400 × 20 m carriageway outline, 1 m between nodes (many chunks), starting at the
  // middle of its south edge: the stretch through the ring's closing point is joined back.
  std::vector<Vector2d> ring;
  for (double x = 0; x < 200; x += 1) ring.emplace_back(x, -10);
  for (double y = -10; y < 10; y += 1) ring.emplace_back(200, y);
  for (double x = 200; x > -200; x -= 1) ring.emplace_back(x, 10);
  for (double y = 10; y > -10; y -= 1) ring.emplace_back(-200, y);
  for (double x = -200; x < 0; x += 1) ring.emplace_back(x, -10);
  LocationMapElements map;
  map.road_boundaries = {boundary_ring(ring)};
  ASSERT_GT(map.road_boundaries[0].chunks.size(), 10u);
  const FrameMapElements got = cut_frame_map({}, map, geometry::Rigid3{}, window, 10);
  ASSERT_EQ(got.areas.size(), 2u);
  for (const FrameArea& a : got.areas) {
    EXPECT_EQ(a.category, AreaCategory::kRoadBoundary);
    EXPECT_GE(a.id, 1'000'000'000);
    ASSERT_GE(a.points.size(), 2u);
    EXPECT_EQ(std::abs(a.points.front().x()), 50.0);
    EXPECT_EQ(std::abs(a.points.back().x()), 50.0);
    EXPECT_NE(a.points.front().x(), a.points.back().x());  // edge to edge, one piece each
  }
  // The north edge runs −x, the south edge (joined across the ring's start) +x.
  const auto south = got.areas[0].points.front().y() < 0 ? got.areas[0] : got.areas[1];
  EXPECT_EQ(south.points.front().x(), -50.0);
  EXPECT_EQ(south.points.size(), 101u);  // every 1 m node from −50 to 50
}

// The defects real maps hold (tests/unit/nuscenes/real_defects_fixture.h): lanes without
// dividers, null polygon links resolving to the map-sized null-token polygon, a hole with no
// nodes, 300 drivable areas of only that polygon. Every lane gets its lines' sources; the
// canvas edge never becomes a road boundary.
TEST(FrameMap, RealMapDefectsGiveNoCanvasEdgeBoundary) {
  test::OJson m = test::OJson::parse(test::small_map_text());
  test::add_real_map_defects(m);
  const double w = m["canvas_edge"][0].get<double>(), h = m["canvas_edge"][1].get<double>();
  test::TempDir root("frame-map-defects");
  const nuscenes::MapExpansion map = nuscenes::load_map_expansion_file(test::write_map(root, m.dump(1)));
  Issues issues;
  const graph::LaneGraph g = graph::build_lane_graph(map, graph::LaneGraphOptions{}, &issues);
  const LocationMapElements e = location_map_elements(map, g);
  EXPECT_EQ(e.left.size(), g.lanes.size());
  EXPECT_EQ(e.half_width_m.size(), g.lanes.size());
  ASSERT_FALSE(e.road_boundaries.empty());  // the small map's own drivable area
  for (const BoundaryRing& ring : e.road_boundaries)
    for (const Vector2d& p : ring.points) EXPECT_FALSE(p.x() == w && p.y() == h) << "the canvas corner";
}

}  // namespace
}  // namespace nsg::frames
