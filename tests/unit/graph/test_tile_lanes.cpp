// A tile graph back into lanes (lane_graph_from_tile) and the adaptive ground truth on it:
// pieces of one token, joins through shared nodes, loops.
#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/graph/projection.h"
#include "nsg/graph/tile_lanes.h"

namespace nsg::graph {
namespace {

TileGraph make_tile(const std::vector<std::array<double, 2>>& xy,
                    const std::vector<std::tuple<int32_t, int32_t, std::string>>& edges) {
  TileGraph t;
  for (size_t k = 0; k < xy.size(); ++k)
    t.nodes.push_back({static_cast<int32_t>(k), xy[k][0] * 5, xy[k][1] * 5, xy[k][0], xy[k][1]});
  for (const auto& [s, d, token] : edges) t.edges.push_back({s, d, token});
  return t;
}

TEST(TileLanes, ChainsPiecesAndJoins) {
  // A: 0→1→2 listed out of order; B and C start where A ends; A again as a separate piece 5→6.
  const TileGraph t = make_tile({{0, 0}, {10, 0}, {20, 0}, {20, 10}, {30, 0}, {50, 0}, {60, 0}},
                                {{1, 2, "A"}, {0, 1, "A"}, {2, 3, "B"}, {2, 4, "C"}, {5, 6, "A"}});
  std::vector<int32_t> tile_edge;
  const LaneGraph g = lane_graph_from_tile(t, TileFrame::kMetres, &tile_edge);
  ASSERT_EQ(g.lanes.size(), 4u);
  EXPECT_EQ(g.lanes[0].token, "A");
  EXPECT_EQ(g.lanes[0].nodes, (std::vector<int32_t>{0, 1, 2}));
  EXPECT_DOUBLE_EQ(g.lanes[0].length_m, 20.0);
  EXPECT_EQ(g.lanes[0].successors, (std::vector<int32_t>{1, 2}));
  EXPECT_EQ(g.lanes[3].token, "A");  // the second piece of A, its own lane
  EXPECT_TRUE(g.lanes[3].successors.empty());
  EXPECT_EQ(tile_edge, (std::vector<int32_t>{1, 0, 2, 3, 4}));
  EXPECT_EQ(lane_graph_from_tile(t, TileFrame::kPixels).nodes[1].x_m, 50.0);

  const SegmentIndex index(g);
  const AdaptiveGroundTruth gt = project_onto_lanes(g, index, {{15, 1}, {5, -1}, {20.5, 5}, {55, 0.5}}, {});
  ASSERT_EQ(gt.points.size(), 4u);
  EXPECT_EQ(gt.points[0].input, 1);
  EXPECT_EQ(gt.points[1].input, 0);
  EXPECT_TRUE(gt.has_connection(0, 1));
  EXPECT_TRUE(gt.has_connection(1, 2));   // across the join into B
  EXPECT_FALSE(gt.has_connection(2, 3));  // pieces of A are not joined
}

TEST(TileLanes, LoopsAndBadIndices) {
  const TileGraph loop = make_tile({{0, 0}, {10, 0}, {10, 10}}, {{0, 1, "R"}, {1, 2, "R"}, {2, 0, "R"}});
  const LaneGraph g = lane_graph_from_tile(loop);
  ASSERT_EQ(g.lanes.size(), 1u);
  EXPECT_EQ(g.lanes[0].nodes, (std::vector<int32_t>{0, 1, 2, 0}));
  TileGraph bad = loop;
  bad.edges[1].target = 9;
  EXPECT_THROW(lane_graph_from_tile(bad), DataError);
}

}  // namespace
}  // namespace nsg::graph
