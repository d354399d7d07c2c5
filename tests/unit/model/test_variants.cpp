// The b2 / graph variants' parts on hand-made geometry: anchors from a score ridge, b2's
// two-nearest-neighbour joins, the graph variant's candidate pairs, pair features and
// connection labels from the adaptive ground truth (along a lane, across a fork, never
// between the two directions of a road), and the variant names.
#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nsg/core/error.h"
#include "nsg/model/anchors.h"
#include "nsg/model/pairs.h"
#include "nsg/model/variants.h"

namespace {

using namespace nsg::model;
using Pt = std::array<double, 2>;
using Pair = std::array<int, 2>;

// A graph of polylines (pixel coordinates), each directed from its first point to its last;
// polylines sharing an end point share the node.
nsg::metrics::Graph lanes(const std::vector<std::vector<Pt>>& lines) {
  nsg::metrics::Graph g;
  auto node = [&](const Pt& p) {
    for (size_t i = 0; i < g.nodes.size(); ++i) {
      if (g.nodes[i].u == p[0] && g.nodes[i].v == p[1]) return static_cast<int64_t>(i);
    }
    g.nodes.push_back({p[0], p[1]});
    return static_cast<int64_t>(g.nodes.size() - 1);
  };
  for (const auto& line : lines) {
    for (size_t k = 1; k < line.size(); ++k) g.edges.push_back({node(line[k - 1]), node(line[k])});
  }
  return g;
}

// Points from a to b every `step` px (a included, b included when it falls on the step).
std::vector<Pt> every(Pt a, Pt b, double step) {
  std::vector<Pt> out;
  const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
  for (double s = 0.0; s <= len + 1e-9; s += step)
    out.push_back({a[0] + (b[0] - a[0]) * s / len, a[1] + (b[1] - a[1]) * s / len});
  return out;
}

bool has(const std::vector<Pair>& pairs, int a, int b) {
  return std::find(pairs.begin(), pairs.end(), Pair{std::min(a, b), std::max(a, b)}) != pairs.end();
}

TEST(Variants, NamesRoundTripAndBadNameNamesTheFlag) {
  for (const char* n : {"b1", "b2", "graph"}) EXPECT_EQ(to_string(parse_variant(n)), n);
  try {
    parse_variant("lanegraphnet");
    FAIL() << "no ConfigError";
  } catch (const nsg::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--variant"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("graph"), std::string::npos) << e.what();
  }
}

TEST(Anchors, TargetPeaksOnTheNodes) {
  const nsg::metrics::Graph g = lanes({{{10, 10}, {20, 10}}});
  EXPECT_FLOAT_EQ(anchor_target(g, 10, 10, 4.0), 1.0f);
  EXPECT_NEAR(anchor_target(g, 15, 10, 4.0), std::exp(-25.0 / 32.0), 1e-6);  // midway: 0.46
  EXPECT_NEAR(anchor_target(g, 20, 14, 4.0), std::exp(-16.0 / 32.0), 1e-6);
  EXPECT_EQ(anchor_target(nsg::metrics::Graph{}, 0, 0, 4.0), 0.0f);
}

TEST(Anchors, RidgeGivesAnchorsOnItNoCloserThanTheRadius) {
  // A horizontal ridge at v = 40 from u = 20 to 100 and a vertical one at u = 90 from v = 60.
  cv::Mat score = cv::Mat::zeros(128, 128, CV_32F);
  for (int v = 0; v < 128; ++v) {
    for (int u = 0; u < 128; ++u) {
      const double h = u >= 20 && u <= 100 ? std::exp(-0.5 * (v - 40) * (v - 40) / 4.0) : 0.0;
      const double w = v >= 60 && v <= 120 ? std::exp(-0.5 * (u - 90) * (u - 90) / 4.0) : 0.0;
      score.at<float>(v, u) = static_cast<float>(0.9 * std::max(h, w));
    }
  }
  AnchorOptions o;
  const std::vector<Pt> a = detect_anchors(score, o);
  ASSERT_GE(a.size(), 8u);  // 80 px + 60 px of ridge at 10 … 20 px spacing
  EXPECT_LE(a.size(), 18u);
  for (size_t i = 0; i < a.size(); ++i) {
    const bool on_h = std::fabs(a[i][1] - 40) <= 1 && a[i][0] >= 19 && a[i][0] <= 101;
    const bool on_v = std::fabs(a[i][0] - 90) <= 1 && a[i][1] >= 59 && a[i][1] <= 121;
    EXPECT_TRUE(on_h || on_v) << a[i][0] << "," << a[i][1];
    for (size_t j = i + 1; j < a.size(); ++j) EXPECT_GE(std::hypot(a[i][0] - a[j][0], a[i][1] - a[j][1]), 10.0);
  }
  // Same map, same anchors (the map is not smoothed in place); nothing on an empty map.
  EXPECT_EQ(detect_anchors(score, o), a);
  EXPECT_TRUE(detect_anchors(cv::Mat::zeros(64, 64, CV_32F), o).empty());
}

TEST(B2, EachAnchorJoinsItsTwoNearestNeighbours) {
  // A row of anchors 12 px apart, a lone anchor far below, and a pair close together.
  const std::vector<Pt> a = {{0, 0}, {12, 0}, {24, 0}, {36, 0}, {18, 80}, {100, 100}, {104, 103}};
  const std::vector<Pair> pairs = nearest_neighbour_pairs(a, 2);
  for (size_t i = 0; i < a.size(); ++i) {
    std::vector<std::pair<double, int>> d;
    for (size_t j = 0; j < a.size(); ++j) {
      if (j != i) d.emplace_back(std::hypot(a[i][0] - a[j][0], a[i][1] - a[j][1]), static_cast<int>(j));
    }
    std::sort(d.begin(), d.end());
    EXPECT_TRUE(has(pairs, static_cast<int>(i), d[0].second)) << i;
    EXPECT_TRUE(has(pairs, static_cast<int>(i), d[1].second)) << i;
  }
  // Nothing else: every pair is some anchor's first or second neighbour.
  EXPECT_EQ(pairs, (std::vector<Pair>{{0, 1}, {0, 2}, {1, 2}, {1, 3}, {1, 4}, {2, 3}, {2, 4}, {4, 5}, {4, 6}, {5, 6}}));
  // b2's graph keeps those joins (all scores high, directions east) and orients them.
  AnchorSet s;
  s.points = {{10, 50}, {22, 50}, {34, 50}, {46, 50}};
  s.scores.assign(4, 0.9);
  Votes east{};
  east[0] = 9;  // bin 0: 0 … 20° from east
  s.votes.assign(4, east);
  s.mean_dir.assign(4, {1.0, -0.17});
  const cv::Mat likelihood(128, 128, CV_32F, cv::Scalar(0.9));
  ExtractionOptions x;
  x.min_piece_length_px = 0;
  const nsg::metrics::Graph g = b2_graph(s, likelihood, AnchorOptions{}, x);
  ASSERT_EQ(g.nodes.size(), 4u);
  EXPECT_EQ(g.edges.size(), 5u);                                              // 0-1 0-2 1-2 1-3 2-3
  for (const auto& e : g.edges) EXPECT_LT(g.nodes[e[0]].u, g.nodes[e[1]].u);  // eastwards
  EXPECT_EQ(g.node_scores, std::vector<double>(4, 0.9));
}

TEST(Pairs, CandidatesWithinTheRadius) {
  const std::vector<Pt> a = {{0, 0}, {30, 0}, {30.5, 0}, {0, 30}, {0, 30.01}};
  EXPECT_EQ(candidate_pairs(a, 30.0), (std::vector<Pair>{{0, 1}, {0, 3}, {1, 2}, {3, 4}}));  // 30 px in, 30.5 out
}

TEST(Pairs, LaneGraphFromTileSplitsAtForksAndLinksSuccessors) {
  // A east to a fork at (60, 100), then B straight on and C turning south.
  const nsg::metrics::Graph g =
      lanes({every({10, 100}, {60, 100}, 10), every({60, 100}, {110, 100}, 10), every({60, 100}, {60, 150}, 10)});
  const nsg::graph::LaneGraph l = lane_graph_from_tile(g);
  ASSERT_EQ(l.lanes.size(), 3u);
  EXPECT_EQ(l.edges.size(), 15u);
  EXPECT_NEAR(l.lanes[0].length_m, 50.0, 1e-9);  // "metres" are pixels here
  EXPECT_EQ(l.lanes[0].successors, (std::vector<int32_t>{1, 2}));
  EXPECT_TRUE(l.lanes[1].successors.empty());
}

TEST(Pairs, LabelsFromTheAdaptiveGroundTruth) {
  // A two-way street: eastbound at v = 50, westbound at v = 67.5 (a 3.5 m lane apart).
  const nsg::metrics::Graph road = lanes({every({0, 50}, {200, 50}, 10), every({200, 67.5}, {0, 67.5}, 10)});
  const std::vector<Pt> a = {{20, 51}, {33, 49}, {47, 50}, {22, 67}, {36, 68}, {100, 150}};
  const std::vector<Pair> pairs = candidate_pairs(a, 30.0);
  const std::vector<int> labels = connection_labels(road, a, pairs, PairOptions{});
  ASSERT_EQ(labels.size(), pairs.size());
  std::set<Pair> connected;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (labels[k]) connected.insert(pairs[k]);
  }
  // Consecutive along each lane; not 0-2 (it skips 1), never across the centre line, and
  // the anchor 80 px away from both lanes is in no pair.
  EXPECT_EQ(connected, (std::set<Pair>{{0, 1}, {1, 2}, {3, 4}}));
  EXPECT_TRUE(has(pairs, 0, 2));
  EXPECT_TRUE(has(pairs, 0, 3));

  // Across a fork: the last anchor before it connects to the first one on each branch.
  const nsg::metrics::Graph fork =
      lanes({every({10, 100}, {60, 100}, 10), every({60, 100}, {110, 100}, 10), every({60, 100}, {60, 150}, 10)});
  const std::vector<Pt> f = {{35, 101}, {50, 100}, {72, 99}, {61, 114}};
  const std::vector<Pair> fp = candidate_pairs(f, 30.0);
  const std::vector<int> fl = connection_labels(fork, f, fp, PairOptions{});
  std::set<Pair> fc;
  for (size_t k = 0; k < fp.size(); ++k) {
    if (fl[k]) fc.insert(fp[k]);
  }
  EXPECT_EQ(fc, (std::set<Pair>{{0, 1}, {1, 2}, {1, 3}}));  // not 2-3: sibling branches
}

TEST(Pairs, FeaturesAreSymmetricAndSeeSkippedAnchors) {
  AnchorSet s;
  s.points = {{20, 50}, {30, 50}, {40, 50}};
  s.scores = {0.8, 0.9, 0.7};
  Votes east{};
  east[0] = 9;
  s.votes.assign(3, east);
  s.mean_dir.assign(3, {1.0, 0.0});
  const cv::Mat like(128, 128, CV_32F, cv::Scalar(0.6));
  const cv::Mat f = pair_features(s, {{0, 1}, {0, 2}, {1, 0}}, like, like);
  ASSERT_EQ(f.cols, static_cast<int>(pair_feature_names().size()));
  const auto col = [&](const std::string& n) {
    const auto names = pair_feature_names();
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  EXPECT_FLOAT_EQ(f.at<float>(0, col("length_px")), 10.0f);
  EXPECT_FLOAT_EQ(f.at<float>(1, col("length_px")), 20.0f);
  EXPECT_FLOAT_EQ(f.at<float>(0, col("anchors_skipped")), 0.0f);
  EXPECT_FLOAT_EQ(f.at<float>(1, col("anchors_skipped")), 1.0f);
  EXPECT_FLOAT_EQ(f.at<float>(1, col("rank_max")), 1.0f);  // 2 is 0's second neighbour
  EXPECT_FLOAT_EQ(f.at<float>(0, col("axis_cos_end_min")), 1.0f);
  EXPECT_NEAR(f.at<float>(0, col("centre_along_mean")), 0.6f, 1e-6);
  for (int c = 0; c < f.cols; ++c) EXPECT_FLOAT_EQ(f.at<float>(0, c), f.at<float>(2, c)) << pair_feature_names()[c];
}

TEST(Pairs, GraphVariantKeepsWhatTheClassifierConnects) {
  AnchorSet s;
  s.points = {{20, 50}, {32, 50}, {44, 50}, {20, 68}};
  s.scores.assign(4, 0.9);
  Votes east{};
  east[0] = 9;
  s.votes.assign(4, east);
  s.mean_dir.assign(4, {1.0, 0.0});
  const cv::Mat like(128, 128, CV_32F, cv::Scalar(0.9));
  // A stand-in classifier: connected iff no anchor is skipped and the pair runs along the lane.
  const auto names = pair_feature_names();
  const int skipped = static_cast<int>(std::find(names.begin(), names.end(), "anchors_skipped") - names.begin());
  const int axis = static_cast<int>(std::find(names.begin(), names.end(), "axis_cos_end_min") - names.begin());
  const PairScorer scorer = [&](const cv::Mat& x) {
    std::vector<double> p;
    for (int r = 0; r < x.rows; ++r)
      p.push_back(x.at<float>(r, skipped) == 0 && x.at<float>(r, axis) > 0.9 ? 0.8 : 0.1);
    return p;
  };
  ExtractionOptions x;
  x.min_piece_length_px = 0;
  const nsg::metrics::Graph g = pair_graph(s, like, like, PairOptions{}, scorer, x);
  ASSERT_EQ(g.edges.size(), 2u);  // 0→1, 1→2; the isolated anchor 3 is dropped
  EXPECT_EQ(g.nodes.size(), 3u);
  EXPECT_EQ(g.edge_scores, (std::vector<double>{0.8, 0.8}));
  for (const auto& e : g.edges) EXPECT_LT(g.nodes[e[0]].u, g.nodes[e[1]].u);
}

}  // namespace
