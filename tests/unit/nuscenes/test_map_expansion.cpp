// Every layer of the hand-written fixture map, with asserted values, and the devkit-style
// accessors (discretize_lanes, discretize_centerlines, get_arcline_path, connectivity).
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/core/error.h"
#include "nsg/nuscenes/map_expansion.h"
#include "test_map_fixture.h"

namespace nsg::nuscenes {
namespace {

constexpr double kPi = 3.141592653589793;

class MapFixture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new test::TempDir("map");
    test::write_map(*root_, test::small_map_text());
    map_ = new MapExpansion(load_map_expansion(root_->path(), "boston-seaport"));
  }
  static void TearDownTestSuite() {
    delete map_;
    delete root_;
  }
  static const MapExpansion& map() { return *map_; }

 private:
  static inline test::TempDir* root_ = nullptr;
  static inline MapExpansion* map_ = nullptr;
};

TEST_F(MapFixture, HeaderFields) {
  EXPECT_EQ(map().location(), "boston-seaport");
  EXPECT_EQ(map().version(), "1.3");
  EXPECT_EQ(map().canvas_edge_m()[0], 2979.5);
  EXPECT_EQ(map().canvas_edge_m()[1], 2118.1);
  EXPECT_EQ(map().file().filename(), "boston-seaport.json");
}

TEST_F(MapFixture, GeometricLayers) {
  ASSERT_EQ(map().nodes().size(), 9u);
  EXPECT_EQ(map().nodes()[2].token, "n3");
  EXPECT_EQ(map().nodes()[2].x_m, 40.0);
  EXPECT_EQ(map().nodes()[2].y_m, 14.0);
  EXPECT_EQ(map().nodes()[8].y_m, 12.5);

  ASSERT_EQ(map().lines().size(), 5u);
  const MapLine& div = map().lines()[map().index_of(MapLayer::kLine, "line-div")];
  EXPECT_EQ(div.node_tokens, (std::vector<std::string>{"n4", "n3"}));
  EXPECT_EQ(div.nodes, (std::vector<MapIndex>{3, 2}));
  EXPECT_TRUE(map().lines()[4].nodes.empty());  // an empty line is allowed (queenstown has some)

  ASSERT_EQ(map().polygons().size(), 8u);
  const MapPolygon& road = map().polygons()[0];
  EXPECT_EQ(road.token, "poly-road");
  EXPECT_EQ(road.exterior_nodes, (std::vector<MapIndex>{0, 1, 4, 5}));
  ASSERT_EQ(road.holes.size(), 1u);
  EXPECT_EQ(road.holes[0].node_tokens, (std::vector<std::string>{"h1", "h2", "h3"}));
  EXPECT_EQ(road.holes[0].nodes, (std::vector<MapIndex>{6, 7, 8}));
  EXPECT_TRUE(map().polygons()[1].holes.empty());
}

TEST_F(MapFixture, AreaLayers) {
  ASSERT_EQ(map().drivable_areas().size(), 1u);
  EXPECT_EQ(map().drivable_areas()[0].polygons, (std::vector<MapIndex>{0, 3}));

  ASSERT_EQ(map().road_segments().size(), 1u);
  const RoadSegment& rs = map().road_segments()[0];
  EXPECT_EQ(rs.polygon, 0u);
  EXPECT_FALSE(rs.is_intersection);
  EXPECT_EQ(rs.drivable_area_token, "da-1");

  ASSERT_EQ(map().road_blocks().size(), 1u);
  const RoadBlock& rb = map().road_blocks()[0];
  EXPECT_EQ(rb.from_edge_line_token, "line-edge-a");
  EXPECT_EQ(rb.to_edge_line_token, "line-edge-b");
  EXPECT_EQ(rb.road_segment_token, "rs-1");

  ASSERT_EQ(map().ped_crossings().size(), 1u);
  EXPECT_EQ(map().ped_crossings()[0].polygon, 4u);
  EXPECT_EQ(map().ped_crossings()[0].road_segment_token, "rs-1");
  ASSERT_EQ(map().walkways().size(), 1u);
  EXPECT_EQ(map().walkways()[0].polygon, 5u);

  ASSERT_EQ(map().carpark_areas().size(), 1u);
  EXPECT_EQ(map().carpark_areas()[0].orientation_rad, 1.5707963267948966);
  EXPECT_EQ(map().carpark_areas()[0].polygon, 7u);
  EXPECT_EQ(map().carpark_areas()[0].road_block_token, "rb-1");
}

TEST_F(MapFixture, LanesAndConnectors) {
  ASSERT_EQ(map().lanes().size(), 2u);
  const Lane& a = map().lanes()[0];
  EXPECT_EQ(a.token, "lane-a");
  EXPECT_EQ(a.polygon, 1u);
  EXPECT_EQ(a.lane_type, "CAR");
  EXPECT_EQ(a.from_edge_line_token, "line-edge-a");
  ASSERT_EQ(a.left_lane_divider_segments.size(), 2u);
  EXPECT_EQ(a.left_lane_divider_segments[0].node_token, "n4");
  EXPECT_EQ(a.left_lane_divider_segments[0].node, 3u);
  EXPECT_EQ(a.left_lane_divider_segments[1].segment_type, "SINGLE_SOLID_WHITE");
  EXPECT_EQ(a.right_lane_divider_segments[1].segment_type, "NIL");
  EXPECT_TRUE(map().lanes()[1].left_lane_divider_segments.empty());

  ASSERT_EQ(map().lane_connectors().size(), 2u);
  EXPECT_EQ(map().lane_connectors()[0].token, "conn-1");
  EXPECT_EQ(map().lane_connectors()[0].polygon, 3u);
  EXPECT_EQ(map().centerline_layer("conn-2"), MapLayer::kLaneConnector);
  EXPECT_EQ(map().centerline_layer("lane-b"), MapLayer::kLane);
  EXPECT_FALSE(map().centerline_layer("rb-1").has_value());
}

TEST_F(MapFixture, StopLinesDividersTrafficLights) {
  ASSERT_EQ(map().stop_lines().size(), 3u);
  EXPECT_EQ(map().stop_lines()[0].stop_line_type, "PED_CROSSING");
  EXPECT_EQ(map().stop_lines()[0].ped_crossing_tokens, (std::vector<std::string>{"pc-1"}));
  EXPECT_EQ(map().stop_lines()[0].road_block_token, "rb-1");
  EXPECT_EQ(map().stop_lines()[1].traffic_light_tokens, (std::vector<std::string>{"tl-1"}));
  EXPECT_EQ(map().stop_lines()[2].stop_line_type, "STOP_SIGN");

  ASSERT_EQ(map().road_dividers().size(), 1u);
  EXPECT_EQ(map().road_dividers()[0].line, 2u);
  EXPECT_EQ(map().road_dividers()[0].road_segment_token, "rs-1");
  ASSERT_EQ(map().lane_dividers().size(), 1u);
  EXPECT_EQ(map().lane_dividers()[0].line, 2u);
  ASSERT_EQ(map().lane_dividers()[0].lane_divider_segments.size(), 2u);
  EXPECT_EQ(map().lane_dividers()[0].lane_divider_segments[1].node, 2u);

  ASSERT_EQ(map().traffic_lights().size(), 1u);
  const TrafficLight& tl = map().traffic_lights()[0];
  EXPECT_EQ(tl.line, 3u);
  EXPECT_EQ(tl.traffic_light_type, "VERTICAL");
  EXPECT_EQ(tl.from_road_block_token, "rb-1");
  ASSERT_EQ(tl.items.size(), 2u);
  EXPECT_EQ(tl.items[0].color, "RED");
  EXPECT_EQ(tl.items[0].shape, "CIRCLE");
  EXPECT_EQ(tl.items[0].rel_pos.tz, 0.3);
  EXPECT_EQ(tl.items[0].to_road_block_tokens, (std::vector<std::string>{"rb-1"}));
  EXPECT_EQ(tl.items[1].shape, "LEFT");
  EXPECT_EQ(tl.pose.tx, 40.0);
  EXPECT_EQ(tl.pose.tz, 3.5);
  EXPECT_EQ(tl.pose.rz, 3.14);
}

TEST_F(MapFixture, TokenLookups) {
  EXPECT_EQ(map().size(MapLayer::kNode), 9u);
  EXPECT_EQ(map().size(MapLayer::kStopLine), 3u);
  EXPECT_EQ(map().find(MapLayer::kPolygon, "poly-park"), 7u);
  EXPECT_FALSE(map().find(MapLayer::kPolygon, "lane-a").has_value());
  try {
    (void)map().index_of(MapLayer::kWalkway, "nope");
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("walkway 'nope'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("boston-seaport.json"), std::string::npos) << e.what();
  }
  EXPECT_EQ(map_layer_name(MapLayer::kLaneConnector), "lane_connector");
}

TEST_F(MapFixture, ArclinePathsAndConnectivity) {
  EXPECT_EQ(map().arcline_path_tokens(), (std::vector<std::string>{"lane-a", "conn-1", "lane-b"}));
  const auto& b = map().get_arcline_path("lane-b");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].shape, geometry::ArclineShape::kRSR);
  EXPECT_EQ(b[1].start_pose.x, 25.0);
  EXPECT_EQ(b[1].end_pose.x, 10.0);
  EXPECT_EQ(b[0].radius_m, 999.999);
  EXPECT_EQ(b[0].segment_length_m[1], 15.0);
  EXPECT_EQ(map().find_arcline_path("conn-2"), nullptr);
  EXPECT_THROW(map().get_arcline_path("conn-2"), DataError);

  EXPECT_EQ(map().connectivity_tokens().size(), 4u);
  EXPECT_EQ(map().outgoing("lane-a"), (std::vector<std::string>{"conn-1"}));
  EXPECT_EQ(map().incoming("lane-b"), (std::vector<std::string>{"conn-1"}));
  EXPECT_TRUE(map().outgoing("conn-2").empty());
  EXPECT_THROW(map().outgoing("no-such-lane"), DataError);
  EXPECT_THROW(map().incoming("no-such-lane"), DataError);
}

TEST_F(MapFixture, DiscretizeLanesLikeTheDevkit) {
  const auto lanes = map().discretize_lanes({"lane-b", "conn-2", "lane-b", "lane-a"}, 2.0);
  ASSERT_EQ(lanes.size(), 3u);  // a dict in the devkit: duplicates collapse
  EXPECT_EQ(lanes[0].token, "lane-b");
  EXPECT_EQ(lanes[0].poses.size(), 9u + 9u);                    // two 15 m paths at 2 m, joint pose repeated
  EXPECT_NEAR(lanes[0].poses[8].x, lanes[0].poses[9].x, 1e-9);  // joint ≈ repeated
  EXPECT_NEAR(lanes[0].poses[8].y, lanes[0].poses[9].y, 1e-9);
  EXPECT_TRUE(lanes[1].poses.empty());  // conn-2 has no arcline path
  EXPECT_EQ(lanes[1].layer, MapLayer::kLaneConnector);
  ASSERT_EQ(lanes[2].poses.size(), 16u);  // 30 m at 2 m
  EXPECT_EQ(lanes[2].poses[0], (geometry::Pose2{10.0, 12.0, 0.0}));
  EXPECT_NEAR(lanes[2].poses[15].x, 40.0, 1e-9);
  // Identical to the geometry function on the stored paths.
  EXPECT_EQ(lanes[2].poses, geometry::discretize_lane(map().get_arcline_path("lane-a"), 2.0));
}

TEST_F(MapFixture, DiscretizeCenterlinesLanesThenConnectors) {
  const auto all = map().discretize_centerlines(0.5);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0].token, "lane-a");
  EXPECT_EQ(all[1].token, "lane-b");
  EXPECT_EQ(all[2].token, "conn-1");
  EXPECT_EQ(all[2].layer, MapLayer::kLaneConnector);
  EXPECT_EQ(all[3].token, "conn-2");
  EXPECT_TRUE(all[3].poses.empty());
  // conn-1: a left half circle of radius 2 from (40, 12) heading east to (40, 16) heading west.
  const auto& u = all[2].poses;
  ASSERT_EQ(u.size(), 14u);  // ceil(2π / 0.5) + 1
  EXPECT_NEAR(u.back().x, 40.0, 1e-9);
  EXPECT_NEAR(u.back().y, 16.0, 1e-9);
  EXPECT_NEAR(std::fabs(u.back().yaw), kPi, 1e-9);
  for (const auto& p : u) EXPECT_NEAR(std::hypot(p.x - 40.0, p.y - 14.0), 2.0, 1e-9);
}

TEST(MapExpansion, LoadFileTakesLocationFromStem) {
  test::TempDir root("map-file");
  const auto file = test::write_map(root, test::small_map_text(), "singapore-onenorth");
  const MapExpansion map = load_map_expansion_file(file);
  EXPECT_EQ(map.location(), "singapore-onenorth");
  EXPECT_EQ(map.lanes().size(), 2u);
}

TEST(MapExpansion, UnknownLocationIsAConfigError) {
  test::TempDir root("map-loc");
  EXPECT_THROW(load_map_expansion(root.path(), "singapore-newton"), ConfigError);
}

TEST(MapExpansion, MissingFileIsAnIoErrorNamingIt) {
  test::TempDir root("map-missing");
  try {
    (void)load_map_expansion(root.path(), "singapore-queenstown");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("maps/expansion/singapore-queenstown.json"), std::string::npos) << e.what();
  }
}

TEST(MapExpansion, NewerVersionsAndUnknownKeysAreAccepted) {
  test::TempDir root("map-new");
  std::string text = test::replace_once(test::small_map_text(), "\"version\": \"1.3\"",
                                        "\"version\": \"1.4\", \"future_layer\": [{\"a\": 1}]");
  text = test::replace_once(text, "\"token\": \"ww-1\",", "\"token\": \"ww-1\", \"extra\": {\"x\": [1, 2]},");
  const MapExpansion map = load_map_expansion_file(test::write_map(root, text));
  EXPECT_EQ(map.version(), "1.4");
  EXPECT_EQ(map.walkways().size(), 1u);
}

}  // namespace
}  // namespace nsg::nuscenes
