// Lane graph attributes on analytic maps where the answer is known: the turn of each lane
// and connector, forks and joins, lane changes between neighbouring lanes of one direction
// (and none to the opposite direction or two lanes over), and what clipping keeps of them.
#include <gtest/gtest.h>

#include <numbers>
#include <set>
#include <utility>

#include "graph_fixtures.h"
#include "nsg/graph/clip.h"
#include "nsg/graph/lane_attributes.h"
#include "nsg/graph/segment_index.h"

namespace nsg::graph {
namespace {

using test::arc;
using test::lane;
using test::straight;
constexpr double kPi = std::numbers::pi;

LaneGraph with_attributes(const std::vector<LaneSource>& sources) {
  LaneGraph g = build_lane_graph(sources, {}, nullptr);
  add_lane_attributes(g);
  return g;
}

TEST(LaneAttributes, TurnsFromTheChangeOfHeading) {
  const LaneGraph g = with_attributes({
      lane("straight", {straight(0, 0, 0, 20)}),
      lane("left", {arc(0, 10, 0, 10, kPi / 2, true)}, {}, {}, true),
      lane("right", {arc(0, 40, 0, 10, kPi / 2, false)}, {}, {}, true),
      lane("u", {arc(0, 80, 0, 6, kPi, true)}, {}, {}, true),
      // 25° and 35° of bend: either side of the 30° line between straight and a turn.
      lane("bend25", {arc(50, 0, 0, 40, 25 * kPi / 180, true)}),
      lane("bend35", {arc(50, 40, 0, 40, 35 * kPi / 180, false)}),
  });
  const auto turn = [&](const char* token) { return g.lanes[g.find_lane(token)].turn; };
  EXPECT_EQ(turn("straight"), Turn::kStraight);
  EXPECT_EQ(turn("left"), Turn::kLeft);
  EXPECT_EQ(turn("right"), Turn::kRight);
  EXPECT_EQ(turn("u"), Turn::kUTurn);
  EXPECT_EQ(turn("bend25"), Turn::kStraight);
  EXPECT_EQ(turn("bend35"), Turn::kRight);
}

TEST(LaneAttributes, SplitsAndMergesAtTheTJunction) {
  // A forks at the origin into c_straight and c_right; c_straight and c_merge join at B's
  // start (20, 0); every other node has one edge in and one out, or is an end.
  const LaneGraph g = with_attributes(test::t_junction());
  std::vector<std::pair<double, double>> splits, merges;
  for (const Node& n : g.nodes) {
    EXPECT_NE(n.junction, Junction::kBoth);
    if (n.junction == Junction::kSplit) splits.push_back({n.x_m, n.y_m});
    if (n.junction == Junction::kMerge) merges.push_back({n.x_m, n.y_m});
  }
  ASSERT_EQ(splits.size(), 1u);
  EXPECT_NEAR(splits[0].first, 0.0, 1e-9);
  EXPECT_NEAR(splits[0].second, 0.0, 1e-9);
  ASSERT_EQ(merges.size(), 1u);
  EXPECT_NEAR(merges[0].first, 20.0, 1e-9);
  EXPECT_NEAR(merges[0].second, 0.0, 1e-9);
  EXPECT_EQ(g.lanes[g.find_lane("c_right")].turn, Turn::kRight);
  EXPECT_EQ(g.lanes[g.find_lane("c_merge")].turn, Turn::kRight);
  EXPECT_EQ(g.lanes[g.find_lane("c_straight")].turn, Turn::kStraight);
  EXPECT_TRUE(g.lane_changes.empty()) << "no two lanes of one direction side by side";
}

TEST(LaneAttributes, LaneChangesOnlyToTheNeighbourOfTheSameDirection) {
  // Three eastbound lanes 3.5 m apart (y = 0, 3.5, 7) and a westbound one at y = −3.5, all
  // 20 m long with nodes every 2 m; and an eastbound connector beside the top lane.
  const LaneGraph g = with_attributes({
      lane("E0", {straight(0, 0, 0, 20)}),
      lane("E1", {straight(0, 3.5, 0, 20)}),
      lane("E2", {straight(0, 7, 0, 20)}),
      lane("W", {straight(20, -3.5, kPi, 20)}),
      lane("conn", {straight(0, 10.5, 0, 20)}, {}, {}, true),
  });
  std::set<std::pair<std::string, std::string>> pairs;
  for (const LaneChange& c : g.lane_changes) {
    pairs.insert({g.lanes[c.source_lane].token, g.lanes[c.target_lane].token});
    const Node& a = g.nodes[c.source];
    const Node& b = g.nodes[c.target];
    EXPECT_NEAR(a.x_m, b.x_m, 1e-9) << "straight across: the nearest node is abreast";
    EXPECT_NEAR(std::abs(a.y_m - b.y_m), 3.5, 1e-9);
    EXPECT_GT(a.x_m, 0.0) << "not from or to a lane's first node";
    EXPECT_LT(a.x_m, 20.0) << "not from or to a lane's last node";
  }
  const std::set<std::pair<std::string, std::string>> want = {{"E0", "E1"}, {"E1", "E0"}, {"E1", "E2"}, {"E2", "E1"}};
  EXPECT_EQ(pairs, want);
  // 11 nodes a lane, the 9 inner ones have a neighbour abreast: 9 per ordered pair.
  EXPECT_EQ(g.lane_changes.size(), 4u * 9u);
  for (size_t k = 1; k < g.lane_changes.size(); ++k)
    EXPECT_LT(std::make_pair(g.lane_changes[k - 1].source, g.lane_changes[k - 1].target),
              std::make_pair(g.lane_changes[k].source, g.lane_changes[k].target));
}

TEST(LaneAttributes, ClippingKeepsAttributesAndLaneChangesInside) {
  const LaneGraph g = with_attributes({
      lane("E0", {straight(0, 0, 0, 20)}),
      lane("E1", {straight(0, 3.5, 0, 20)}),
      lane("c", {arc(20, 0, 0, 10, kPi / 2, true)}, {}, {}, true),
  });
  // x in [5, 15]: nodes at x = 6, 8, 10, 12, 14 of each lane are inside, 5 lane changes
  // each way; the connector lies outside.
  const TileGraph t = clip_to_tile(g, SegmentIndex(g), {5.0, -2.0, 15.0, 6.0});
  EXPECT_EQ(t.lane_changes.size(), 10u);
  for (const TileLaneChange& c : t.lane_changes) {
    EXPECT_NEAR(std::abs(t.nodes[c.source].y_m - t.nodes[c.target].y_m), 3.5, 1e-9);
    EXPECT_NE(c.from_lane_token, c.to_lane_token);
  }
  for (const TileEdge& e : t.edges) {
    EXPECT_FALSE(e.is_connector);
    EXPECT_EQ(e.turn, Turn::kStraight);
  }
  const TileGraph corner = clip_to_tile(g, SegmentIndex(g), {19.0, -1.0, 31.0, 11.0});
  bool connector = false;
  for (const TileEdge& e : corner.edges)
    if (e.lane_token == "c") {
      connector = true;
      EXPECT_TRUE(e.is_connector);
      EXPECT_EQ(e.turn, Turn::kLeft);
    }
  EXPECT_TRUE(connector);
}

TEST(LaneAttributes, NamesRoundTrip) {
  for (Turn t : {Turn::kStraight, Turn::kLeft, Turn::kRight, Turn::kUTurn}) {
    Turn back = Turn::kStraight;
    ASSERT_TRUE(turn_from_name(turn_name(t), &back));
    EXPECT_EQ(back, t);
  }
  for (Junction j : {Junction::kNone, Junction::kSplit, Junction::kMerge, Junction::kBoth}) {
    Junction back = Junction::kNone;
    ASSERT_TRUE(junction_from_name(junction_name(j), &back));
    EXPECT_EQ(back, j);
  }
  Turn t;
  EXPECT_FALSE(turn_from_name("sideways", &t));
}

}  // namespace
}  // namespace nsg::graph
