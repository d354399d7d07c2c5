// LaneGraphNet's C++ post-processing on hand-made maps: anchors decoded from a heatmap and
// its offsets (threshold, peaks, NMS, row-major order, votes), the pair pooling on known
// feature maps, and the graph from pair scores (the paper's direction rule, the cut).
#include <cmath>

#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/model/net_graph.h"

namespace {

using namespace nsg::model;

NetMaps blank_maps(int cells, int direction_class) {
  NetMaps m;
  m.heat = cv::Mat::zeros(cells, cells, CV_32F);
  m.offset_u = cv::Mat::zeros(cells, cells, CV_32F);
  m.offset_v = cv::Mat::zeros(cells, cells, CV_32F);
  for (int k = 0; k < kDirectionClasses; ++k)
    m.direction.push_back(cv::Mat(cells, cells, CV_32F, cv::Scalar(k == direction_class ? 1.0 : 0.0)));
  m.tile_size_px = cells * 4;
  return m;
}

TEST(NetGraph, AnchorsFromPeaksWithOffsetsNmsAndThreshold) {
  NetMaps m = blank_maps(16, 0);
  m.heat.at<float>(10, 10) = 0.5f;   // kept: (41.5, 41.5)
  m.heat.at<float>(10, 11) = 0.45f;  // a neighbour, not a peak
  m.heat.at<float>(12, 11) = 0.4f;   // a peak, but 4.5 px from the first after its offset
  m.offset_u.at<float>(12, 11) = -0.5f;
  m.offset_v.at<float>(12, 11) = -1.0f;
  m.heat.at<float>(2, 3) = 0.9f;  // kept: (3.25·4 + 1.5, 1.75·4 + 1.5)
  m.offset_u.at<float>(2, 3) = 0.25f;
  m.offset_v.at<float>(2, 3) = -0.25f;
  m.heat.at<float>(5, 14) = 0.29f;  // below the threshold
  const AnchorSet a = net_anchors(m, NetGraphOptions{});
  ASSERT_EQ(a.points.size(), 2u);
  EXPECT_DOUBLE_EQ(a.points[0][0], 14.5);  // row-major cell order, not score order
  EXPECT_DOUBLE_EQ(a.points[0][1], 8.5);
  EXPECT_DOUBLE_EQ(a.points[1][0], 41.5);
  EXPECT_DOUBLE_EQ(a.points[1][1], 41.5);
  EXPECT_NEAR(a.scores[0], 0.9, 1.0 / 4096);
  EXPECT_NEAR(a.scores[1], 0.5, 1.0 / 4096);
  EXPECT_FLOAT_EQ(a.votes[0][0], 9.0f);  // 3 × 3 cells of probability 1 for class 0
  EXPECT_GT(a.mean_dir[0][0], 0.0);      // class 0 is 0–20°: eastwards
}

TEST(NetGraph, PairInputsPoolAlongTheSegment) {
  const cv::Mat constant(8, 8, CV_32F, cv::Scalar(2.0));
  cv::Mat ramp(8, 8, CV_32F);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c) ramp.at<float>(r, c) = static_cast<float>(c);
  // a at cell (0, 0), b at cell (0, 2): interior samples at cell u = 0.5, 1, 1.5
  const cv::Mat x = net_pair_inputs({constant, ramp}, {{1.5, 1.5}, {9.5, 1.5}}, {{0, 1}}, NetGraphOptions{});
  ASSERT_EQ(x.rows, 1);
  ASSERT_EQ(x.cols, 9);
  const float expected[9] = {4.0f, 2.0f, 0.0f, 2.0f, 2.0f, 1.0f, 2.0f, 1.5f, 8.0f / 30.0f};
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(x.at<float>(0, k), expected[k], 1e-6) << "column " << k;
}

TEST(NetGraph, GraphKeepsAcceptedPairsOrientedByTheVotes) {
  AnchorSet a;
  a.points = {{10.0, 10.0}, {20.0, 10.0}, {30.0, 10.0}};
  a.scores = {0.9, 0.9, 0.9};
  Votes west{};
  west[9] = 1.0f;  // 180–200°
  a.votes = {west, west, west};
  for (const auto& v : a.votes) a.mean_dir.push_back(mean_direction_px(v));
  const nsg::metrics::Graph g = net_graph(a, {{0, 1}, {1, 2}, {0, 2}}, {0.9, 0.8, 0.3}, 64, NetGraphOptions{});
  ASSERT_EQ(g.nodes.size(), 3u);
  ASSERT_EQ(g.edges.size(), 2u);                          // the pair scoring 0.3 is not an edge
  EXPECT_EQ(g.edges[0], (std::array<int64_t, 2>{1, 0}));  // westwards
  EXPECT_EQ(g.edges[1], (std::array<int64_t, 2>{2, 1}));
  EXPECT_DOUBLE_EQ(g.edge_scores[0], 0.9);
  EXPECT_DOUBLE_EQ(g.edge_scores[1], 0.8);
  EXPECT_THROW(net_graph(a, {{0, 3}}, {0.9}, 64, NetGraphOptions{}), nsg::DataError);
}

TEST(NetGraph, ShortcutsAcrossAnIntermediateAnchorAreRemoved) {
  // a → b → c along one lane, b 1 px off the segment a–c; d 8 px off a–e's segment.
  const std::vector<std::array<double, 2>> pts = {{10, 10}, {20, 11}, {30, 10}, {40, 18}, {50, 10}};
  const std::vector<std::array<int, 2>> pairs = {{0, 1}, {1, 2}, {0, 2}, {2, 3}, {3, 4}, {2, 4}};
  EXPECT_EQ(non_shortcut_pairs(pts, pairs, 6.0), (std::vector<bool>{true, true, false, true, true, true}));
  EXPECT_EQ(non_shortcut_pairs(pts, pairs, 10.0), (std::vector<bool>{true, true, false, true, true, false}));
  EXPECT_EQ(non_shortcut_pairs(pts, pairs, 0.0), std::vector<bool>(6, true));  // off
  // Only pairs accepted with both ends count: without b → c, a → c is a connection of its own.
  EXPECT_EQ(non_shortcut_pairs(pts, {{0, 1}, {0, 2}}, 6.0), (std::vector<bool>{true, true}));

  AnchorSet a;
  a.points = {{10.0, 10.0}, {20.0, 11.0}, {30.0, 10.0}};
  a.scores = {0.9, 0.9, 0.9};
  Votes east{};
  east[0] = 1.0f;  // 0–20°
  a.votes = {east, east, east};
  for (const auto& v : a.votes) a.mean_dir.push_back(mean_direction_px(v));
  const nsg::metrics::Graph g = net_graph(a, {{0, 1}, {1, 2}, {0, 2}}, {0.9, 0.8, 0.95}, 128, NetGraphOptions{});
  ASSERT_EQ(g.edges.size(),
            2u);  // a → c accepted by the head (0.95), removed as a shortcut (128 px tile: 20 px edges allowed)
  EXPECT_EQ(g.edges[0], (std::array<int64_t, 2>{0, 1}));
  EXPECT_EQ(g.edges[1], (std::array<int64_t, 2>{1, 2}));
  NetGraphOptions off;
  off.shortcut_radius_px = 0.0;
  EXPECT_EQ(net_graph(a, {{0, 1}, {1, 2}, {0, 2}}, {0.9, 0.8, 0.95}, 128, off).edges.size(), 3u);
  off.shortcut_radius_px = -1.0;
  EXPECT_THROW(off.validate(), nsg::ConfigError);
}

}  // namespace
