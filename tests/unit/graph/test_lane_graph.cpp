#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "graph_fixtures.h"
#include "nsg/core/error.h"
#include "nsg/graph/lane_graph.h"

namespace nsg::graph {
namespace {

using test::arc;
using test::lane;
using test::straight;

double node_distance(const Node& a, const Node& b) { return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m); }

TEST(LaneGraph, StraightLaneOf25mHas14NodesEvenlySpaced) {
  Issues issues;
  const LaneGraph g = build_lane_graph({lane("L", {straight(100, 200, 0.3, 25)})}, {}, &issues);
  ASSERT_EQ(g.nodes.size(), 14u);
  ASSERT_EQ(g.edges.size(), 13u);
  for (const Edge& e : g.edges) {
    EXPECT_NEAR(g.edge_length_m(e), 25.0 / 13.0, 1e-9);  // 1.923 m
    EXPECT_EQ(g.lanes[e.lane].token, "L");
  }
  EXPECT_NEAR(g.nodes.front().x_m, 100.0, 1e-12);
  EXPECT_NEAR(g.nodes.back().x_m, 100 + 25 * std::cos(0.3), 1e-9);
  EXPECT_NEAR(g.nodes.back().y_m, 200 + 25 * std::sin(0.3), 1e-9);
  EXPECT_EQ(issues.count_check("graph.isolated_lane"), 1u);
}

TEST(LaneGraph, QuarterCircleNodesLieOnTheCircle) {
  constexpr double kR = 10.0;
  const LaneGraph g =
      build_lane_graph({lane("Q", {arc(kR, 0, std::numbers::pi / 2, kR, std::numbers::pi / 2, true)})}, {}, nullptr);
  const double length = g.lanes[0].length_m;
  EXPECT_NEAR(length, kR * std::numbers::pi / 2, 0.01);  // chords of 0.5 m
  EXPECT_EQ(g.nodes.size(), static_cast<size_t>(std::ceil(length / 2.0)) + 1);
  for (const Node& n : g.nodes) EXPECT_NEAR(std::hypot(n.x_m, n.y_m), kR, 0.004);  // chord sagitta
  EXPECT_LE(g.max_edge_length_m(), 2.0 + 1e-9);
  EXPECT_NEAR(g.nodes.back().x_m, 0.0, 1e-9);
  EXPECT_NEAR(g.nodes.back().y_m, kR, 1e-9);
}

TEST(LaneGraph, JointPoseBetweenPathsIsNotDuplicated) {
  const std::vector<Node> line = joined_centerline({straight(0, 0, 0, 3), straight(3, 0, 0, 3)}, 1.0);
  ASSERT_EQ(line.size(), 7u);  // 4 + 4 poses minus the repeated joint
  for (size_t i = 1; i < line.size(); ++i) EXPECT_NEAR(line[i].x_m - line[i - 1].x_m, 1.0, 1e-12);
}

TEST(LaneGraph, ResampleRespectsCapAndCount) {
  const std::vector<Node> poly{{0, 0}, {3, 0}, {3, 4}};  // length 7
  const std::vector<Node> out = resample_polyline(poly, 2.0);
  ASSERT_EQ(out.size(), 5u);  // ceil(7 / 2) + 1
  for (size_t i = 1; i < out.size(); ++i) EXPECT_LE(node_distance(out[i - 1], out[i]), 1.75 + 1e-12);
  EXPECT_EQ(out.back().y_m, 4.0);
}

TEST(LaneGraph, TJunctionForksAndMerges) {
  Issues issues;
  const LaneGraph g = build_lane_graph(test::t_junction(), {}, &issues);
  EXPECT_TRUE(issues.empty()) << issues.format();
  std::vector<int> out_degree(g.nodes.size(), 0), in_degree(g.nodes.size(), 0);
  for (const Edge& e : g.edges) {
    ++out_degree[e.source];
    ++in_degree[e.target];
  }
  const int32_t a = g.find_lane("A"), b = g.find_lane("B"), c = g.find_lane("C"), d = g.find_lane("D");
  EXPECT_EQ(out_degree[g.lanes[a].nodes.back()], 2);  // fork
  EXPECT_EQ(in_degree[g.lanes[b].nodes.front()], 2);  // merge
  // C starts where D ends, but no connectivity joins them: two nodes.
  EXPECT_NE(g.lanes[c].nodes.front(), g.lanes[d].nodes.back());
  // Every connectivity pair is a path: A's end is the connector's start, and so on.
  for (const LaneSource& src : test::t_junction())
    for (const std::string& next : src.outgoing)
      EXPECT_EQ(g.lanes[g.find_lane(src.token)].nodes.back(), g.lanes[g.find_lane(next)].nodes.front())
          << src.token << " -> " << next;
  EXPECT_LE(g.max_edge_length_m(), 2.0 + 1e-9);
  // Node count per lane = ceil(length / 2) + 1.
  for (const Lane& l : g.lanes)
    EXPECT_EQ(l.nodes.size(), static_cast<size_t>(std::ceil(l.length_m / 2.0)) + 1) << l.token;
  std::set<std::pair<int32_t, int32_t>> unique_edges;
  for (const Edge& e : g.edges) unique_edges.insert({e.source, e.target});
  EXPECT_EQ(unique_edges.size(), g.edges.size());
}

TEST(LaneGraph, MapDefectsAreCollected) {
  std::vector<LaneSource> map{
      lane("A", {straight(0, 0, 0, 10)}, {"B", "ghost"}, {}),
      lane("B", {straight(10.5, 0, 0, 10)}, {}, {}),  // 0.5 m gap, incoming not mirrored
      lane("E", {}, {}, {}),                          // no arcline path
      lane("F", {straight(50, 50, 0, 4)}, {}, {}),    // isolated
  };
  Issues issues;
  const LaneGraph g = build_lane_graph(map, {}, &issues);
  EXPECT_EQ(issues.count_check("graph.dangling_connectivity"), 1u);
  EXPECT_EQ(issues.count_check("graph.unmirrored_connectivity"), 1u);
  EXPECT_EQ(issues.count_check("graph.ends_apart"), 1u);
  EXPECT_EQ(issues.count_check("graph.no_arcline_path"), 1u);
  EXPECT_GE(issues.count_check("graph.isolated_lane"), 1u);
  EXPECT_TRUE(g.lanes[g.find_lane("E")].nodes.empty());
  EXPECT_NE(issues.format().find("ghost"), std::string::npos);

  LaneGraphOptions strict;
  strict.strict = true;
  try {
    build_lane_graph(map, strict, nullptr, "maps/expansion/boston-seaport.json");
    FAIL() << "strict mode must throw";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("boston-seaport.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("A"), std::string::npos);
  }
}

TEST(LaneGraph, OptionsValidate) {
  LaneGraphOptions o;
  o.max_spacing_m = 0.0;
  EXPECT_THROW(o.validate(), ConfigError);
}

}  // namespace
}  // namespace nsg::graph
