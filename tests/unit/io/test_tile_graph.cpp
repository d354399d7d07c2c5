// io's one reader and writer of <key>.graph.json: the attributes and lane changes survive a
// round trip, a graph written before them reads with their defaults, and a bad attribute is
// refused naming the file and its JSON path.
#include <set>

#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/core/issues.h"
#include "nsg/io/tile_graph.h"

namespace nsg::io {
namespace {

graph::TileGraph sample_graph() {
  graph::TileGraph g;
  g.nodes = {{0, 1.5, 2.5, 100.0, 200.0, graph::Junction::kSplit},
             {1, 11.5, 2.5, 102.0, 200.0, graph::Junction::kNone},
             {2, 1.5, 20.0, 100.0, 196.5, graph::Junction::kMerge},
             {3, 11.5, 20.0, 102.0, 196.5, graph::Junction::kBoth}};
  g.edges = {{0, 1, "lane-a", false, false, graph::Turn::kStraight}, {2, 3, "conn-b", true, true, graph::Turn::kUTurn}};
  g.lane_changes = {{0, 2, "lane-a", "conn-b"}, {3, 1, "conn-b", "lane-a"}};
  return g;
}

TEST(TileGraph, AttributesAndLaneChangesRoundTrip) {
  const graph::TileGraph g = sample_graph();
  const std::string text = tile_graph_text("boston-seaport-test-000000", g);
  const graph::TileGraph back = tile_graph_from_json(nlohmann::json::parse(text), "t.graph.json");
  ASSERT_EQ(back.nodes.size(), 4u);
  for (size_t k = 0; k < 4; ++k) EXPECT_EQ(back.nodes[k].junction, g.nodes[k].junction) << k;
  ASSERT_EQ(back.edges.size(), 2u);
  EXPECT_FALSE(back.edges[0].is_connector);
  EXPECT_TRUE(back.edges[1].is_connector);
  EXPECT_TRUE(back.edges[1].in_intersection);
  EXPECT_EQ(back.edges[1].turn, graph::Turn::kUTurn);
  ASSERT_EQ(back.lane_changes.size(), 2u);
  EXPECT_EQ(back.lane_changes[1].source, 3);
  EXPECT_EQ(back.lane_changes[1].target, 1);
  EXPECT_EQ(back.lane_changes[1].from_lane_token, "conn-b");
  EXPECT_TRUE(back.has_edge_attributes);
  EXPECT_EQ(tile_graph_text("boston-seaport-test-000000", back), text) << "the writer is the reader's inverse";
  EXPECT_NE(text.find(R"("kind":"connector","in_intersection":true,"turn":"u_turn")"), std::string::npos) << text;
}

TEST(TileGraph, AGraphWithoutAttributesReadsWithTheirDefaults) {
  const graph::TileGraph g = tile_graph_from_json(nlohmann::json::parse(R"({"schema_version": "1",
      "key": "boston-seaport-test-000000", "nodes": [{"id": 0, "u": 0, "v": 0, "x": 0, "y": 0},
      {"id": 1, "u": 1, "v": 0, "x": 0.2, "y": 0}], "edges": [{"source": 0, "target": 1, "lane_token": "l"}]})"),
                                                  "old.graph.json");
  EXPECT_EQ(g.nodes[0].junction, graph::Junction::kNone);
  EXPECT_FALSE(g.edges[0].is_connector);
  EXPECT_FALSE(g.edges[0].in_intersection);
  EXPECT_EQ(g.edges[0].turn, graph::Turn::kStraight);
  EXPECT_TRUE(g.lane_changes.empty());
  // Defaults, not facts: the scorer's per-class recalls must not take them for lanes.
  EXPECT_FALSE(g.has_edge_attributes);
}

TEST(TileGraph, BadAttributesAreRefusedByPath) {
  const auto refused_at = [](const std::string& edit_path, const nlohmann::json& value) {
    nlohmann::json doc = nlohmann::json::parse(tile_graph_text("boston-seaport-test-000000", sample_graph()));
    doc[nlohmann::json::json_pointer(edit_path)] = value;
    try {
      tile_graph_from_json(doc, "t.graph.json");
    } catch (const DataError& e) {
      EXPECT_EQ(e.file(), "t.graph.json");
      return e.record();
    }
    return std::string();
  };
  EXPECT_EQ(refused_at("/nodes/1/junction", "fork"), "/nodes/1/junction");
  EXPECT_EQ(refused_at("/edges/0/kind", "road"), "/edges/0/kind");
  EXPECT_EQ(refused_at("/edges/1/in_intersection", 1), "/edges/1/in_intersection");
  EXPECT_EQ(refused_at("/edges/1/turn", "sharp_left"), "/edges/1/turn");
  EXPECT_EQ(refused_at("/lane_changes/0/target", 9), "/lane_changes/0/target");
  EXPECT_EQ(refused_at("/lane_changes/1/to_lane_token", nullptr), "/lane_changes/1/to_lane_token");
  EXPECT_EQ(refused_at("/lane_changes", "none"), "/lane_changes");
}

// validate's way: every reference problem listed in one pass, the elements they spoil
// left out, the rest read; a shape problem still throws.
TEST(TileGraph, ReferenceProblemsAreListedWhenCollected) {
  nlohmann::json doc = nlohmann::json::parse(tile_graph_text("boston-seaport-test-000000", sample_graph()));
  const size_t nodes = doc["nodes"].size(), edges = doc["edges"].size(), changes = doc["lane_changes"].size();
  ASSERT_GE(nodes, 2u);
  ASSERT_GE(changes, 1u);
  doc["edges"][0]["target"] = 99;
  doc["edges"].push_back({{"source", 77}, {"target", 0}, {"lane_token", "x"}});
  doc["lane_changes"][0]["source"] = -4;
  doc["nodes"].push_back(doc["nodes"][1]);  // its id again
  Issues problems;
  const graph::TileGraph g = tile_graph_from_json(doc, "t.graph.json", &problems);
  EXPECT_EQ(problems.size(), 4u) << problems.format();
  EXPECT_EQ(problems.count_check("graph.indices"), 3u) << problems.format();
  EXPECT_EQ(problems.count_check("graph.lane_changes"), 1u) << problems.format();
  std::set<std::string> subjects;
  for (const Issue& i : problems.items()) subjects.insert(i.subject);
  EXPECT_EQ(subjects,
            (std::set<std::string>{
                "t.graph.json:/edges/0/target", "t.graph.json:/edges/" + std::to_string(edges) + "/source",
                "t.graph.json:/lane_changes/0/source", "t.graph.json:/nodes/" + std::to_string(nodes) + "/id"}));
  EXPECT_EQ(g.nodes.size(), nodes + 1);
  EXPECT_EQ(g.edges.size(), edges - 1);
  EXPECT_EQ(g.lane_changes.size(), changes - 1);
  // Without a list the first of them throws, as before.
  EXPECT_THROW(tile_graph_from_json(doc, "t.graph.json"), DataError);
  doc["nodes"][0]["x"] = "east";
  Issues shape;
  EXPECT_THROW(tile_graph_from_json(doc, "t.graph.json", &shape), DataError);
}

}  // namespace
}  // namespace nsg::io
