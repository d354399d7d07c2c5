#include <gtest/gtest.h>

#include "graph_fixtures.h"
#include "nsg/graph/projection.h"

namespace nsg::graph {
namespace {

using test::lane;
using test::straight;

TEST(Projection, PointsProjectOrthogonallyAndChainAlongTheLane) {
  const LaneGraph g = build_lane_graph({lane("L", {straight(0, 0, 0, 20)})}, {}, nullptr);
  const SegmentIndex index(g);
  // Given out of order, on both sides of the lane; the last one is too far away.
  const std::vector<Node> points{{12.3, 1.0}, {2.5, -0.7}, {7.0, 0.2}, {5.0, 9.0}};
  const AdaptiveGroundTruth gt = project_onto_lanes(g, index, points, {});
  ASSERT_EQ(gt.points.size(), 3u);
  EXPECT_EQ(gt.points[0].input, 1);
  EXPECT_EQ(gt.points[1].input, 2);
  EXPECT_EQ(gt.points[2].input, 0);
  EXPECT_NEAR(gt.points[0].x_m, 2.5, 1e-12);
  EXPECT_NEAR(gt.points[0].y_m, 0.0, 1e-12);
  EXPECT_NEAR(gt.points[2].along_lane_m, 12.3, 1e-9);
  EXPECT_NEAR(gt.points[1].distance_m, 0.2, 1e-12);
  EXPECT_TRUE(gt.has_connection(0, 1));
  EXPECT_TRUE(gt.has_connection(1, 2));
  EXPECT_FALSE(gt.has_connection(1, 0));
  EXPECT_FALSE(gt.has_connection(0, 2));
  EXPECT_EQ(gt.connections.size(), 2u);
}

TEST(Projection, ConnectionsFollowConnectivityThroughEmptyConnectors) {
  const LaneGraph g = build_lane_graph(test::t_junction(), {}, nullptr);
  const SegmentIndex index(g);
  // One point on A, none on the connectors, one on B and one on C.
  const std::vector<Node> points{{-5, 0.3}, {30, -0.2}, {10.4, -25}};
  const AdaptiveGroundTruth gt = project_onto_lanes(g, index, points, {});
  ASSERT_EQ(gt.points.size(), 3u);
  auto index_of = [&](int input) {
    for (size_t k = 0; k < gt.points.size(); ++k)
      if (gt.points[k].input == input) return static_cast<int32_t>(k);
    return -1;
  };
  EXPECT_TRUE(gt.has_connection(index_of(0), index_of(1)));  // A → c_straight → B
  EXPECT_TRUE(gt.has_connection(index_of(0), index_of(2)));  // A → c_right → C (fork)
  EXPECT_EQ(gt.connections.size(), 2u);
  // Connectors of 20 m and 15.7 m without points exceed a 10 m budget: no connections.
  ProjectionOptions near;
  near.max_follow_m = 10.0;
  EXPECT_TRUE(project_onto_lanes(g, index, points, near).connections.empty());
}

}  // namespace
}  // namespace nsg::graph
