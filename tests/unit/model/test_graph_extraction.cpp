// Skeleton to graph on drawn shapes of known topology, anchors, orientation from votes, and
// the paper's post-processing on small hand-built graphs.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nsg/core/error.h"
#include "nsg/model/graph_extraction.h"

namespace {

using namespace nsg::model;

constexpr int kSize = 128;

cv::Mat blank() { return cv::Mat::zeros(kSize, kSize, CV_8U); }

void draw(cv::Mat& mask, cv::Point a, cv::Point b) { cv::line(mask, a, b, cv::Scalar(255), 5); }

SkeletonGraph skeleton_of(const cv::Mat& mask, double min_spur_px = 6.0) {
  SkeletonGraph g = trace_skeleton(thin(mask));
  prune_spurs(g, min_spur_px);
  return g;
}

std::vector<int> degrees(const SkeletonGraph& g) {
  std::vector<int> d(g.vertices.size(), 0);
  for (const auto& b : g.branches) {
    ++d[static_cast<size_t>(b.a)];
    ++d[static_cast<size_t>(b.b)];
  }
  return d;
}

std::vector<int> sorted(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  return v;
}

double length(const std::vector<cv::Point2d>& pts) {
  double len = 0.0;
  for (size_t k = 1; k < pts.size(); ++k) len += cv::norm(pts[k] - pts[k - 1]);
  return len;
}

// Connected components of the branch graph (every vertex counts).
int components(size_t vertices, const std::vector<std::array<int, 2>>& links) {
  std::vector<int> parent(vertices);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[static_cast<size_t>(x)] != x)
      x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  };
  int n = static_cast<int>(vertices);
  for (const auto& [a, b] : links) {
    const int ra = find(a), rb = find(b);
    if (ra != rb) {
      parent[static_cast<size_t>(ra)] = rb;
      --n;
    }
  }
  return n;
}

int components(const SkeletonGraph& g) {
  std::vector<std::array<int, 2>> links;
  for (const auto& b : g.branches) links.push_back({b.a, b.b});
  return components(g.vertices.size(), links);
}

// Every branch's polyline starts at its first vertex and ends at its second; its steps
// are pixel steps (≤ √2) except next to a junction vertex (a mean position).
void expect_well_formed(const SkeletonGraph& g) {
  for (const auto& b : g.branches) {
    ASSERT_GE(b.a, 0);
    ASSERT_GE(b.b, 0);
    ASSERT_LT(static_cast<size_t>(b.a), g.vertices.size());
    ASSERT_LT(static_cast<size_t>(b.b), g.vertices.size());
    ASSERT_GE(b.points.size(), 2u);
    EXPECT_EQ(b.points.front(), g.vertices[static_cast<size_t>(b.a)]);
    EXPECT_EQ(b.points.back(), g.vertices[static_cast<size_t>(b.b)]);
    for (size_t k = 2; k + 1 < b.points.size(); ++k)
      EXPECT_LE(cv::norm(b.points[k] - b.points[k - 1]), std::sqrt(2.0) + 1e-9);
  }
  for (int d : degrees(g)) EXPECT_GT(d, 0) << "an unused vertex";
}

double distance_to(const cv::Point2d& p, double u, double v) { return std::hypot(p.x - u, p.y - v); }

TEST(ModelSkeleton, StraightLineIsOneBranch) {
  cv::Mat mask = blank();
  draw(mask, {20, 64}, {108, 64});
  const SkeletonGraph g = skeleton_of(mask);
  expect_well_formed(g);
  ASSERT_EQ(g.vertices.size(), 2u);
  ASSERT_EQ(g.branches.size(), 1u);
  const auto& b = g.branches[0];
  EXPECT_NE(b.a, b.b);
  // Thinning keeps the axis; the round caps shorten it by at most the half width.
  EXPECT_NEAR(length(b.points), 88.0, 5.0);
  for (const auto& p : b.points) EXPECT_NEAR(p.y, 64.0, 1.0);
  const double left = std::min(g.vertices[0].x, g.vertices[1].x), right = std::max(g.vertices[0].x, g.vertices[1].x);
  EXPECT_NEAR(left, 20.0, 3.0);
  EXPECT_NEAR(right, 108.0, 3.0);
}

TEST(ModelSkeleton, TeeHasOneJunctionOfDegreeThree) {
  cv::Mat mask = blank();
  draw(mask, {20, 40}, {108, 40});
  draw(mask, {64, 40}, {64, 110});
  const SkeletonGraph g = skeleton_of(mask);
  expect_well_formed(g);
  ASSERT_EQ(g.vertices.size(), 4u);
  EXPECT_EQ(g.branches.size(), 3u);
  const std::vector<int> d = degrees(g);
  EXPECT_EQ(sorted(d), (std::vector<int>{1, 1, 1, 3}));
  const size_t junction = static_cast<size_t>(std::max_element(d.begin(), d.end()) - d.begin());
  EXPECT_LT(distance_to(g.vertices[junction], 64, 40), 3.0);
  EXPECT_EQ(components(g), 1);
}

TEST(ModelSkeleton, CrossHasOneJunctionOfDegreeFour) {
  cv::Mat mask = blank();
  draw(mask, {20, 20}, {108, 108});
  draw(mask, {20, 108}, {108, 20});
  const SkeletonGraph g = skeleton_of(mask);
  expect_well_formed(g);
  const std::vector<int> d = degrees(g);
  EXPECT_EQ(sorted(d), (std::vector<int>{1, 1, 1, 1, 4}));
  EXPECT_EQ(g.branches.size(), 4u);
  const size_t junction = static_cast<size_t>(std::max_element(d.begin(), d.end()) - d.begin());
  EXPECT_LT(distance_to(g.vertices[junction], 64, 64), 3.0);
}

TEST(ModelSkeleton, PlusHasOneJunctionOfDegreeFour) {
  cv::Mat mask = blank();
  draw(mask, {20, 64}, {108, 64});
  draw(mask, {64, 20}, {64, 108});
  const SkeletonGraph g = skeleton_of(mask);
  expect_well_formed(g);
  EXPECT_EQ(sorted(degrees(g)), (std::vector<int>{1, 1, 1, 1, 4}));
  EXPECT_EQ(g.branches.size(), 4u);
}

TEST(ModelSkeleton, ClosedCircleIsOneLoop) {
  cv::Mat mask = blank();
  cv::circle(mask, {64, 64}, 35, cv::Scalar(255), 5);
  const SkeletonGraph g = skeleton_of(mask);
  expect_well_formed(g);
  ASSERT_EQ(g.branches.size(), 1u);
  ASSERT_EQ(g.vertices.size(), 1u);
  const auto& b = g.branches[0];
  EXPECT_EQ(b.a, b.b);
  EXPECT_EQ(b.points.front(), b.points.back());
  // The traced polyline takes 4-connected steps around staircase corners, so its length
  // lies between the circumference and the Manhattan perimeter 8r.
  EXPECT_GT(length(b.points), 0.95 * 2 * M_PI * 35);
  EXPECT_LT(length(b.points), 8 * 35);
  for (const auto& p : b.points) EXPECT_NEAR(distance_to(p, 64, 64), 35.0, 2.0);
}

TEST(ModelSkeleton, TwoDisjointLinesAreTwoComponents) {
  cv::Mat mask = blank();
  draw(mask, {15, 30}, {110, 30});
  draw(mask, {15, 90}, {110, 100});
  const SkeletonGraph g = skeleton_of(mask);
  expect_well_formed(g);
  EXPECT_EQ(g.vertices.size(), 4u);
  EXPECT_EQ(g.branches.size(), 2u);
  EXPECT_EQ(components(g), 2);
}

TEST(ModelSkeleton, ShortSpursArePrunedIsolatedPiecesKept) {
  // A one-pixel skeleton: a line on row 64, a 3-px stub down from (60, 64), and a
  // separate 4-px piece.
  cv::Mat sk = blank();
  for (int u = 20; u <= 100; ++u) sk.at<uint8_t>(64, u) = 255;
  for (int v = 65; v <= 67; ++v) sk.at<uint8_t>(v, 60) = 255;
  for (int u = 30; u <= 33; ++u) sk.at<uint8_t>(100, u) = 255;
  SkeletonGraph g = trace_skeleton(sk);
  expect_well_formed(g);
  EXPECT_EQ(g.branches.size(), 4u);  // left, right, stub, piece
  EXPECT_EQ(sorted(degrees(g)), (std::vector<int>{1, 1, 1, 1, 1, 3}));
  prune_spurs(g, 6.0);
  expect_well_formed(g);
  ASSERT_EQ(g.branches.size(), 3u);  // the stub is gone
  EXPECT_EQ(sorted(degrees(g)), (std::vector<int>{1, 1, 1, 1, 2}));
  double total = 0.0;
  for (const auto& b : g.branches) total += length(b.points);
  EXPECT_NEAR(total, 80.0 + 3.0, 1e-9);
  for (const auto& v : g.vertices) EXPECT_NE(v, cv::Point2d(60, 67));  // the stub's end vertex is dropped
}

TEST(ModelSkeleton, AnchorsAtMostSpacingApartAndEndsAtVertices) {
  cv::Mat mask = blank();
  draw(mask, {20, 40}, {108, 40});
  draw(mask, {64, 40}, {64, 110});
  cv::circle(mask, {30, 100}, 15, cv::Scalar(255), 5);
  const SkeletonGraph g = skeleton_of(mask);
  for (const double spacing : {4.0, 10.0}) {
    SCOPED_TRACE(spacing);
    const AnchorGraph a = place_anchors(g, spacing, 1.0);
    // The skeleton vertices come first, unchanged.
    ASSERT_GE(a.nodes.size(), g.vertices.size());
    for (size_t i = 0; i < g.vertices.size(); ++i) {
      EXPECT_EQ(a.nodes[i][0], g.vertices[i].x);
      EXPECT_EQ(a.nodes[i][1], g.vertices[i].y);
    }
    std::vector<int> degree(a.nodes.size(), 0);
    double total = 0.0;
    for (const auto& [i, j] : a.pairs) {
      ASSERT_NE(i, j);
      const double d = std::hypot(a.nodes[static_cast<size_t>(i)][0] - a.nodes[static_cast<size_t>(j)][0],
                                  a.nodes[static_cast<size_t>(i)][1] - a.nodes[static_cast<size_t>(j)][1]);
      EXPECT_LE(d, spacing + 1e-9);
      EXPECT_GT(d, 0.0);
      total += d;
      ++degree[static_cast<size_t>(i)];
      ++degree[static_cast<size_t>(j)];
    }
    // Vertices keep the branch degree (a loop's vertex counts twice); anchors in between
    // are chain links of degree 2.
    const std::vector<int> vd = degrees(g);
    for (size_t i = 0; i < a.nodes.size(); ++i) EXPECT_EQ(degree[i], i < vd.size() ? vd[i] : 2) << i;
    // Same topology: the T and the ring.
    std::vector<std::array<int, 2>> links(a.pairs.begin(), a.pairs.end());
    EXPECT_EQ(components(a.nodes.size(), links), 2);
    // The chords follow the skeleton: within a few % of its length.
    double skeleton_len = 0.0;
    for (const auto& b : g.branches) skeleton_len += length(b.points);
    EXPECT_NEAR(total, skeleton_len, 0.1 * skeleton_len);
  }
}

// The same votes at every anchor: 8 for `bin`, 2 for background.
DirectionVotes constant_votes(int bin) {
  Votes v{};
  v[static_cast<size_t>(bin)] = 8;
  v[kBackgroundClass] = 2;
  return [v](const std::vector<std::array<double, 2>>& anchors) { return std::vector<Votes>(anchors.size(), v); };
}

cv::Mat likelihood_line(cv::Point a, cv::Point b, float value) {
  cv::Mat l = cv::Mat::zeros(kSize, kSize, CV_32F);
  cv::line(l, a, b, cv::Scalar(value), 5);
  return l;
}

TEST(ModelExtraction, EdgesFollowTheVotesAndCarryTheLikelihood) {
  struct Case {
    cv::Point a, b;
    int bin;
    double du, dv;  // the voted travel direction in pixels
  };
  // West (180°–200° → bin 9, centre 190°), south (bin 13, 270°), north-east (bin 2, 50°).
  for (const Case& c : {Case{{10, 64}, {118, 64}, 9, -1, 0}, Case{{64, 8}, {64, 120}, 13, 0, 1},
                        Case{{15, 110}, {110, 15}, 2, 1, -1}}) {
    SCOPED_TRACE(c.bin);
    const cv::Mat likelihood = likelihood_line(c.a, c.b, 0.9f);
    const DirectionVotes votes = constant_votes(c.bin);
    const nsg::metrics::Graph g = extract_graph(likelihood, votes, ExtractionOptions{});
    const double line_len = cv::norm(c.b - c.a);
    ASSERT_GE(g.edges.size(), static_cast<size_t>(line_len / 10.0) - 1);
    ASSERT_EQ(g.node_scores.size(), g.nodes.size());
    ASSERT_EQ(g.edge_scores.size(), g.edges.size());
    EXPECT_EQ(g.nodes.size(), g.edges.size() + 1);  // one chain
    std::vector<int> in(g.nodes.size(), 0), out(g.nodes.size(), 0);
    for (size_t e = 0; e < g.edges.size(); ++e) {
      const auto& p = g.nodes[static_cast<size_t>(g.edges[e][0])];
      const auto& q = g.nodes[static_cast<size_t>(g.edges[e][1])];
      EXPECT_GT((q.u - p.u) * c.du + (q.v - p.v) * c.dv, 0.0) << "edge " << e << " against the votes";
      EXPECT_LE(std::hypot(q.u - p.u, q.v - p.v), 10.0 + 1e-9);
      // A chord may graze the band's edge where the simplified diagonal leaves the axis.
      EXPECT_NEAR(g.edge_scores[e], 0.9, 0.01);
      EXPECT_LE(g.edge_scores[e], 0.9 + 1e-6);
      ++out[static_cast<size_t>(g.edges[e][0])];
      ++in[static_cast<size_t>(g.edges[e][1])];
    }
    for (size_t i = 0; i < g.nodes.size(); ++i) {
      EXPECT_NEAR(g.node_scores[i], 0.9, 0.01);  // bilinear at off-pixel anchors on the diagonal
      EXPECT_LE(in[i], 1);
      EXPECT_LE(out[i], 1);
    }
  }
}

TEST(ModelExtraction, BelowThresholdOrTinyGivesNoGraph) {
  const DirectionVotes votes = constant_votes(0);
  EXPECT_TRUE(extract_graph(likelihood_line({10, 64}, {118, 64}, 0.3f), votes, ExtractionOptions{}).nodes.empty());
  cv::Mat speck = cv::Mat::zeros(kSize, kSize, CV_32F);
  speck(cv::Rect(60, 60, 3, 3)).setTo(0.9f);  // 9 px < min_component_px
  EXPECT_TRUE(extract_graph(speck, votes, ExtractionOptions{}).nodes.empty());
  EXPECT_TRUE(extract_graph(cv::Mat::zeros(kSize, kSize, CV_32F), votes, ExtractionOptions{}).edges.empty());
}

TEST(ModelExtraction, OptionsAndInputAreValidated) {
  const DirectionVotes votes = constant_votes(0);
  ExtractionOptions bad;
  bad.threshold = 1.0;
  EXPECT_THROW(bad.validate(), nsg::ConfigError);
  bad = ExtractionOptions{};
  bad.anchor_spacing_px = 0.5;
  EXPECT_THROW(bad.validate(), nsg::ConfigError);
  EXPECT_THROW(extract_graph(likelihood_line({10, 64}, {118, 64}, 0.9f), votes, bad), nsg::ConfigError);
  EXPECT_THROW(extract_graph(cv::Mat::zeros(kSize, kSize, CV_8U), votes, ExtractionOptions{}), nsg::DataError);
  EXPECT_THROW(extract_graph(cv::Mat::zeros(kSize, kSize / 2, CV_32F), votes, ExtractionOptions{}), nsg::DataError);
}

TEST(ModelExtraction, PostprocessDropsLowScoresLongEdgesAndIsolatedNodes) {
  // The paper's four rules alone (the piece-length rule off); a 128-px tile: edges
  // longer than 32 px go.
  ExtractionOptions paper;
  paper.min_piece_length_px = 0.0;
  nsg::metrics::Graph g;
  auto node = [&](double u, double v, double score) {
    g.nodes.push_back({u, v});
    g.node_scores.push_back(score);
  };
  node(10, 10, 0.9);   // 0 kept
  node(20, 10, 0.9);   // 1 kept
  node(30, 10, 0.4);   // 2 node score < 0.5: dropped with its edge
  node(40, 10, 0.9);   // 3 its only edge has score 0.1: isolated → dropped
  node(50, 10, 0.9);   // 4 its edges are dropped → dropped
  node(100, 10, 0.9);  // 5 only a 50-px edge → dropped
  node(60, 60, 0.9);   // 6 never connected → dropped
  node(70, 60, 0.9);   // 7 kept
  node(80, 60, 0.9);   // 8 kept
  node(10, 100, 0.5);  // 9 exactly the node threshold: kept
  node(42, 100, 0.9);  // 10 32 px from 9: exactly a quarter tile, kept
  g.edges = {{0, 1}, {1, 2}, {3, 4}, {4, 5}, {8, 7}, {9, 10}};
  g.edge_scores = {0.8, 0.8, 0.1, 0.8, 0.2, 0.6};
  const nsg::metrics::Graph input = g;
  postprocess(g, 128, paper);
  ASSERT_EQ(g.nodes.size(), 6u);
  const std::vector<std::pair<double, double>> expected_nodes = {{10, 10}, {20, 10},  {70, 60},
                                                                 {80, 60}, {10, 100}, {42, 100}};
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    EXPECT_EQ(g.nodes[i].u, expected_nodes[i].first) << i;
    EXPECT_EQ(g.nodes[i].v, expected_nodes[i].second) << i;
  }
  EXPECT_EQ(g.node_scores, (std::vector<double>{0.9, 0.9, 0.9, 0.9, 0.5, 0.9}));
  EXPECT_EQ(g.edges, (std::vector<std::array<int64_t, 2>>{{0, 1}, {3, 2}, {4, 5}}));  // direction kept
  EXPECT_EQ(g.edge_scores, (std::vector<double>{0.8, 0.2, 0.6}));

  // With the default piece rule (20 px), the two 10-px pieces go too; the 32-px one stays.
  g = input;
  postprocess(g, 128, ExtractionOptions{});
  ASSERT_EQ(g.nodes.size(), 2u);
  EXPECT_EQ(g.nodes[0].u, 10);
  EXPECT_EQ(g.nodes[0].v, 100);
  EXPECT_EQ(g.edges, (std::vector<std::array<int64_t, 2>>{{0, 1}}));

  // Thresholds come from the options; a larger tile allows the long edge.
  nsg::metrics::Graph h;
  h.nodes = {{0, 0}, {50, 0}};
  h.node_scores = {0.6, 0.6};
  h.edges = {{0, 1}};
  h.edge_scores = {0.3};
  nsg::metrics::Graph h2 = h;
  postprocess(h2, 256, ExtractionOptions{});
  EXPECT_EQ(h2.edges.size(), 1u);
  h2 = h;
  postprocess(h2, 128, ExtractionOptions{});
  EXPECT_TRUE(h2.nodes.empty());
  ExtractionOptions strict;
  strict.min_edge_score = 0.5;
  h2 = h;
  postprocess(h2, 256, strict);
  EXPECT_TRUE(h2.edges.empty());
  EXPECT_TRUE(h2.nodes.empty());
  ExtractionOptions picky;
  picky.min_node_score = 0.7;
  h2 = h;
  postprocess(h2, 256, picky);
  EXPECT_TRUE(h2.nodes.empty());
}

TEST(ModelExtraction, EdgesAcrossThePredictedDirectionAreDropped) {
  // Two horizontal pairs and one vertical pair; every anchor votes east (bins 0 and 17).
  AnchorGraph a;
  a.nodes = {{10, 50}, {40, 50}, {70, 50}, {70, 80}};
  a.pairs = {{1, 0}, {1, 2}, {2, 3}};
  const cv::Mat likelihood(128, 128, CV_32F, cv::Scalar(0.8f));
  Votes east{};
  east[0] = east[17] = 5;
  const DirectionVotes votes = [&](const std::vector<std::array<double, 2>>& anchors) {
    EXPECT_EQ(anchors, a.nodes);  // asked once, for every anchor
    return std::vector<Votes>(anchors.size(), east);
  };
  std::vector<double> angle;
  nsg::metrics::Graph g = orient_and_score(a, likelihood, votes, &angle);
  ASSERT_EQ(g.edges.size(), 3u);
  EXPECT_EQ(g.edges[0], (std::array<int64_t, 2>{0, 1}));  // flipped to point east
  EXPECT_EQ(g.edges[1], (std::array<int64_t, 2>{1, 2}));
  EXPECT_EQ(g.edges[2], (std::array<int64_t, 2>{2, 3}));  // a tie keeps the placed order
  ASSERT_EQ(angle.size(), 3u);
  EXPECT_NEAR(angle[0], 0.0, 1e-6);
  EXPECT_NEAR(angle[1], 0.0, 1e-6);
  EXPECT_NEAR(angle[2], 90.0, 1e-6);
  for (double s : g.node_scores) EXPECT_NEAR(s, 0.8, 1e-6);
  for (double s : g.edge_scores) EXPECT_NEAR(s, 0.8, 1e-6);
  nsg::metrics::Graph filtered = g;
  postprocess(filtered, 128, ExtractionOptions{}, &angle);
  EXPECT_EQ(filtered.edges, (std::vector<std::array<int64_t, 2>>{{0, 1}, {1, 2}}));
  EXPECT_EQ(filtered.nodes.size(), 3u);
  // 90 switches the rule off; without angles it cannot apply.
  ExtractionOptions off;
  off.max_direction_angle_deg = 90.0;
  filtered = g;
  postprocess(filtered, 128, off, &angle);
  EXPECT_EQ(filtered.edges.size(), 3u);
  filtered = g;
  postprocess(filtered, 128, ExtractionOptions{});
  EXPECT_EQ(filtered.edges.size(), 3u);
}

}  // namespace
