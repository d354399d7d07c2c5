// The lane graph over what real maps hold (docs/nuscenes-input.md "Map expansion v1.3"):
// disconnected lanes are infos that --strict lets through, lanes and connectors chain in
// any order, mm gaps between a predecessor's end and a successor's start are joined,
// 4.4e-5 m arcline segments are harmless, dangling connectivity is skipped and reported,
// and the map's own load defects come first in the list.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "../nuscenes/real_defects_fixture.h"
#include "../nuscenes/test_map_fixture.h"
#include "graph_fixtures.h"
#include "nsg/core/error.h"
#include "nsg/graph/from_map.h"

namespace nsg::graph {
namespace {

using test::lane;
using test::straight;

TEST(GraphRealDefects, DisconnectedLanesAreInfosThatStrictAccepts) {
  // Two isolated subgraphs: a single lane, and a pair joined to each other only.
  const std::vector<LaneSource> map{
      lane("alone", {straight(0, 0, 0, 10)}),
      lane("p", {straight(100, 0, 0, 4)}, {"q"}, {}),
      lane("q", {straight(104, 0, 0, 4)}, {}, {"p"}),
  };
  Issues issues;
  LaneGraphOptions strict;
  strict.strict = true;
  const LaneGraph g = build_lane_graph(map, strict, &issues);
  ASSERT_EQ(issues.size(), 1u) << issues.format();
  EXPECT_EQ(issues.items()[0].check, "graph.isolated_lane");
  EXPECT_EQ(issues.items()[0].subject, "alone");
  EXPECT_EQ(issues.items()[0].severity, Severity::kInfo);
  EXPECT_EQ(g.nodes.size(), 6u + 3u + 3u - 1u);  // 10 m → 6 nodes; 4 m → 3 each, one shared
  EXPECT_EQ(g.lanes[1].nodes.back(), g.lanes[2].nodes.front());
}

// lane → lane → connector → connector, with a 3 mm gap and a 4.4e-5 m first segment.
TEST(GraphRealDefects, AnyLaneConnectorOrderTinySegmentsAndMillimetreGaps) {
  const double gap = 0.003, tiny = 4.4e-5;
  const std::vector<LaneSource> map{
      lane("a", {straight(0, 0, 0, 6)}, {"b"}, {}),
      lane("b", {straight(6 + gap, 0, 0, 6)}, {"c"}, {"a"}),
      lane("c", {straight(12 + gap, 0, 0, tiny), straight(12 + gap + tiny, 0, 0, 5)}, {"d"}, {"b"}, true),
      lane("d", {straight(17 + gap + tiny, 0, 0, 5)}, {}, {"c"}, true),
  };
  Issues issues;
  const LaneGraph g = build_lane_graph(map, {}, &issues);
  EXPECT_TRUE(issues.empty()) << issues.format();
  ASSERT_EQ(g.lanes.size(), 4u);
  for (size_t i = 0; i + 1 < g.lanes.size(); ++i) {
    EXPECT_EQ(g.lanes[i].nodes.back(), g.lanes[i + 1].nodes.front()) << i;
    EXPECT_EQ(g.lanes[i].successors, std::vector<int32_t>{static_cast<int32_t>(i + 1)});
  }
  // 6 m, 6 m, 5.000044 m, 5 m: 4 nodes each, plus one splitting b's first edge, which the
  // 3 mm join stretched to 2.003 m.
  EXPECT_EQ(g.lanes[0].nodes.size(), 4u);
  EXPECT_EQ(g.lanes[1].nodes.size(), 5u);
  EXPECT_NEAR(g.edge_length_m(g.edges[3]), (2.0 + gap) / 2, 1e-12);
  EXPECT_EQ(g.lanes[2].nodes.size(), 4u);
  EXPECT_EQ(g.lanes[3].nodes.size(), 4u);
  EXPECT_NEAR(g.lanes[2].length_m, 5.0 + tiny, 1e-12);
  EXPECT_EQ(g.nodes.size(), nsg::test::RealMapDefects::kIslandNodes);
  EXPECT_EQ(g.edges.size(), nsg::test::RealMapDefects::kIslandEdges);
  for (const Edge& e : g.edges) {
    EXPECT_GT(g.edge_length_m(e), 1.0);  // no sliver edge from the tiny segment
    EXPECT_LE(g.edge_length_m(e), 2.0 + 1e-9);
  }
  // A 6 cm gap is beyond the 5 cm tolerance: reported, not joined.
  std::vector<LaneSource> apart = map;
  apart[1] = lane("b", {straight(6.06, 0, 0, 6 + gap - 0.06)}, {"c"}, {"a"});  // same end
  Issues apart_issues;
  const LaneGraph h = build_lane_graph(apart, {}, &apart_issues);
  EXPECT_EQ(apart_issues.count_check("graph.ends_apart"), 1u);
  EXPECT_NE(h.lanes[0].nodes.back(), h.lanes[1].nodes.front());
}

class GraphOnDefectMap : public ::testing::Test {
 protected:
  void SetUp() override {
    nsg::test::OJson m = nsg::test::OJson::parse(nsg::test::small_map_text());
    nsg::test::add_real_map_defects(m);
    file_ = nsg::test::write_map(root_, m.dump(1));
    map_ = std::make_unique<nuscenes::MapExpansion>(nuscenes::load_map_expansion_file(file_));
  }
  nsg::test::TempDir root_{"graph-real-defects"};
  std::filesystem::path file_;
  std::unique_ptr<nuscenes::MapExpansion> map_;
};

TEST_F(GraphOnDefectMap, MapIssuesComeFirstThenTheGraphsOwn) {
  Issues issues;
  const LaneGraph g = build_lane_graph(*map_, {}, &issues);
  const size_t from_map = map_->issues().size();
  ASSERT_GT(issues.size(), from_map);
  for (size_t i = 0; i < from_map; ++i) EXPECT_EQ(issues.items()[i].check, map_->issues().items()[i].check);
  for (size_t i = from_map; i < issues.size(); ++i) EXPECT_EQ(issues.items()[i].check.rfind("graph.", 0), 0u);
  EXPECT_EQ(issues.count_check("graph.dangling_connectivity"), 2u);
  EXPECT_NE(issues.format().find(nsg::test::RealMapDefects::kGhostOut), std::string::npos);
  // The good edge next to the dangling one is kept: lane-a's end is conn-1's start.
  const Lane& a = g.lanes[g.find_lane("lane-a")];
  EXPECT_EQ(a.successors, std::vector<int32_t>{g.find_lane("conn-1")});
  EXPECT_EQ(a.nodes.back(), g.lanes[g.find_lane("conn-1")].nodes.front());
  const Lane& island = g.lanes[g.find_lane(nsg::test::RealMapDefects::kIslandA)];
  EXPECT_EQ(island.nodes.back(), g.lanes[g.find_lane(nsg::test::RealMapDefects::kIslandB)].nodes.front());
}

TEST_F(GraphOnDefectMap, StrictStopsOnTheFirstMapWarningNamingTheFile) {
  LaneGraphOptions strict;
  strict.strict = true;
  try {
    (void)build_lane_graph(*map_, strict, nullptr);
    FAIL() << "strict must throw on the map's warnings";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), file_.string());
    const std::string what = e.what();
    EXPECT_NE(what.find("map.empty_line"), std::string::npos) << what;  // the first warning
    EXPECT_NE(what.find("--strict"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace nsg::graph
