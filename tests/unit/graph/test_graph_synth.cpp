// The lane graph on the synthetic release: built from the map the
// synth command writes, read back through the map expansion reader.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <utility>
#include <nlohmann/json.hpp>

#include "nsg/graph/clip.h"
#include "nsg/graph/from_map.h"
#include "nsg/graph/lane_attributes.h"
#include "test_support.h"

namespace nsg::graph {
namespace {

class GraphOnSynth : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new nsg::test::TempDir("graph-synth");
    const auto config = nsg::test::source_dir() / "samples/synth/tiny.json";
    location_ = nlohmann::json::parse(std::ifstream(config))["location"].get<std::string>();
    map_ = new nuscenes::MapExpansion(nuscenes::load_map_expansion(nsg::test::tiny_release(), location_));
  }
  static void TearDownTestSuite() {
    delete map_;
    delete dir_;
  }
  static nsg::test::TempDir* dir_;
  static nuscenes::MapExpansion* map_;
  static std::string location_;
};
nsg::test::TempDir* GraphOnSynth::dir_ = nullptr;
nuscenes::MapExpansion* GraphOnSynth::map_ = nullptr;
std::string GraphOnSynth::location_;

TEST_F(GraphOnSynth, EdgesAtMostTwoMetresAndNoDefects) {
  Issues defects;
  const LaneGraph g = build_lane_graph(*map_, {}, &defects);
  ASSERT_GT(g.edges.size(), 100u);
  EXPECT_LE(g.max_edge_length_m(), 2.0 + 1e-9);
  EXPECT_EQ(defects.count(Severity::kError), 0u) << defects.format();
  for (const Issue& i : defects.items()) EXPECT_NE(i.check, "graph.ends_apart") << i.message;
  for (const Lane& lane : g.lanes)
    EXPECT_EQ(lane.nodes.size(), static_cast<size_t>(std::ceil(lane.length_m / 2.0)) + 1) << lane.token;
}

TEST_F(GraphOnSynth, EveryConnectivityPairIsAPath) {
  const LaneGraph g = build_lane_graph(*map_, {}, nullptr);
  size_t pairs = 0;
  for (const LaneSource& s : lane_sources(*map_)) {
    const Lane& from = g.lanes[g.find_lane(s.token)];
    for (const std::string& next : s.outgoing) {
      const Lane& to = g.lanes[g.find_lane(next)];
      EXPECT_EQ(from.nodes.back(), to.nodes.front()) << s.token << " -> " << next;
      ++pairs;
    }
  }
  EXPECT_GT(pairs, 10u);
}

TEST_F(GraphOnSynth, ClippingPreservesInsideLength) {
  const LaneGraph g = build_lane_graph(*map_, {}, nullptr);
  const SegmentIndex index(g);
  const double w = map_->canvas_edge_m()[0], h = map_->canvas_edge_m()[1];
  const double tile = 51.2;
  double sum = 0.0;
  for (double y = 0; y < h; y += tile)
    for (double x = 0; x < w; x += tile) sum += clip_to_tile(g, index, {x, y, x + tile, y + tile}).total_length_m();
  double total = 0.0;
  for (const Edge& e : g.edges) total += g.edge_length_m(e);
  // Tiles share borders (closed boxes); edges exactly on a border would count twice,
  // which the axis-aligned synthetic grid avoids by lane offsets.
  EXPECT_NEAR(sum, total, 1e-6 * static_cast<double>(g.edges.size()));
}

}  // namespace
}  // namespace nsg::graph

namespace nsg::graph {
namespace {

TEST_F(GraphOnSynth, InspectGraphCommandReportsCountsAndWritesGeoJson) {
  const auto release = nsg::test::tiny_release().string();
  const auto geojson = (dir_->path() / "lanes.geojson").string();
  const auto r = nsg::test::run_nsgraph(
      {"inspect", "graph", "--dataroot", release, "--location", location_, "--geojson", geojson, "--strict"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  const LaneGraph g = build_lane_graph(*map_, {}, nullptr);
  EXPECT_EQ(out["nodes"].get<size_t>(), g.nodes.size());
  EXPECT_EQ(out["edges"].get<size_t>(), g.edges.size());
  EXPECT_LE(out["max_edge_length_m"].get<double>(), 2.0 + 1e-9);
  EXPECT_TRUE(out["defects"].empty());
  EXPECT_EQ(out["lane_changes"].get<size_t>(), g.lane_changes.size());
  // One feature per edge (kind "successor"), per lane change and per fork or join.
  const nlohmann::json doc = nlohmann::json::parse(std::ifstream(geojson));
  std::map<std::string, size_t> kinds;
  for (const nlohmann::json& f : doc["features"]) ++kinds[f["properties"]["kind"].get<std::string>()];
  EXPECT_EQ(kinds["successor"], g.edges.size());
  EXPECT_EQ(kinds["lane_change"], g.lane_changes.size());
  size_t junctions = 0;
  for (const Node& n : g.nodes) junctions += n.junction != Junction::kNone;
  EXPECT_EQ(kinds["junction"], junctions);
  EXPECT_EQ(out["junctions"]["split"].get<size_t>() + out["junctions"]["merge"].get<size_t>() +
                out["junctions"]["both"].get<size_t>(),
            junctions);

  // A bbox keeps only the clipped part.
  const auto clipped = nsg::test::run_nsgraph(
      {"inspect", "graph", "--dataroot", release, "--location", location_, "--bbox", "100,100,151.2,151.2"});
  ASSERT_EQ(clipped.exit_code, 0) << clipped.err;
  EXPECT_LT(nlohmann::json::parse(clipped.out)["edges"].get<size_t>(), g.edges.size());
}

// The synthetic city's construction says what the attributes must be: connectors join the
// streets inside the crossings (straight on, left and right), lanes run between crossings
// and, with two lanes a direction on some streets, have neighbours to change into.
TEST_F(GraphOnSynth, AttributesFollowTheCitysConstruction) {
  const LaneGraph g = build_lane_graph(*map_, {}, nullptr);
  std::map<Turn, size_t> connector_turns;
  size_t connectors = 0, connectors_inside = 0, lanes_inside = 0;
  for (const Lane& lane : g.lanes) {
    if (lane.is_connector) ++connector_turns[lane.turn];
    connectors += lane.is_connector;
    connectors_inside += lane.is_connector && lane.in_intersection;
    lanes_inside += !lane.is_connector && lane.in_intersection;
  }
  EXPECT_GT(connector_turns[Turn::kStraight], 0u);
  EXPECT_GT(connector_turns[Turn::kLeft], 0u);
  EXPECT_GT(connector_turns[Turn::kRight], 0u);
  EXPECT_EQ(connectors_inside, connectors) << "every connector lies in a crossing";
  EXPECT_EQ(lanes_inside, 0u) << "no lane's middle lies in a crossing";
  size_t splits = 0, merges = 0;
  for (const Node& n : g.nodes) {
    splits += n.junction == Junction::kSplit || n.junction == Junction::kBoth;
    merges += n.junction == Junction::kMerge || n.junction == Junction::kBoth;
  }
  EXPECT_GT(splits, 0u);
  EXPECT_GT(merges, 0u);
  ASSERT_GT(g.lane_changes.size(), 0u);
  for (const LaneChange& c : g.lane_changes) {
    EXPECT_FALSE(g.lanes[c.source_lane].is_connector);
    EXPECT_FALSE(g.lanes[c.target_lane].is_connector);
    const Node& a = g.nodes[c.source];
    const Node& b = g.nodes[c.target];
    // Lanes 3.5 m apart with nodes at most 2 m apart along them: about a lane width (a
    // little less or more across a ring corner's concentric lanes), never two.
    EXPECT_GE(std::hypot(a.x_m - b.x_m, a.y_m - b.y_m), 3.4);
    EXPECT_LE(std::hypot(a.x_m - b.x_m, a.y_m - b.y_m), 4.0);
  }
}

TEST_F(GraphOnSynth, InspectGraphBadInputExitsTwo) {
  const auto release = nsg::test::tiny_release().string();
  auto r = nsg::test::run_nsgraph({"inspect", "graph", "--dataroot", release, "--location", "atlantis"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("atlantis"), std::string::npos);
  r = nsg::test::run_nsgraph({"inspect", "graph", "--dataroot", release, "--location", location_, "--bbox", "1,2,x,4"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--bbox"), std::string::npos);
  r = nsg::test::run_nsgraph({"inspect", "graph", "--dataroot", dir_->path().string(), "--location", location_});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(location_ + ".json"), std::string::npos);
}

}  // namespace
}  // namespace nsg::graph
