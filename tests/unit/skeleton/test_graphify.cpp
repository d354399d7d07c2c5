// graphify on masks drawn from known lane graphs, scored against those graphs with the
// metrics library (APLS, undirected); noisy probability maps; the map readers on good and
// hostile files.
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "graph_masks.h"
#include "nsg/core/error.h"
#include "nsg/skeleton/graphify.h"
#include "test_support.h"

namespace {

using nsg::skeleton::graphify;
using nsg::skeleton::GraphifyOptions;
using nsg::skeleton::read_map_file;

// Every edge has its reverse, and no edge repeats (the undirected output's promise).
void expect_undirected(const nsg::metrics::Graph& g) {
  std::set<std::array<int64_t, 2>> edges(g.edges.begin(), g.edges.end());
  EXPECT_EQ(edges.size(), g.edges.size());
  for (const auto& e : g.edges) EXPECT_TRUE(edges.count({e[1], e[0]})) << e[0] << " -> " << e[1];
}

// A graph's shape: its connected pieces and the most distinct neighbours of a node.
struct Shape {
  int pieces = 0;
  size_t max_degree = 0;
};
Shape shape_of(const nsg::metrics::Graph& g) {
  std::vector<std::set<int64_t>> near(g.nodes.size());
  for (const auto& e : g.edges) {
    near[static_cast<size_t>(e[0])].insert(e[1]);
    near[static_cast<size_t>(e[1])].insert(e[0]);
  }
  Shape s;
  std::vector<char> seen(g.nodes.size(), 0);
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    s.max_degree = std::max(s.max_degree, near[i].size());
    if (seen[i]) continue;
    ++s.pieces;
    std::vector<int64_t> stack{static_cast<int64_t>(i)};
    seen[i] = 1;
    while (!stack.empty()) {
      const int64_t n = stack.back();
      stack.pop_back();
      for (int64_t m : near[static_cast<size_t>(n)]) {
        if (seen[static_cast<size_t>(m)]) continue;
        seen[static_cast<size_t>(m)] = 1;
        stack.push_back(m);
      }
    }
  }
  return s;
}

GraphifyOptions without_crossing_rule() {
  GraphifyOptions o;
  o.skeleton.split_crossings = false;
  return o;
}

TEST(Graphify, CleanMasksOfKnownGraphsScoreAplsAtLeast095) {
  for (const nsg::test::GraphCase& c : nsg::test::graph_cases()) {
    for (int width_px : {5, 7, 9}) {
      const nsg::metrics::Graph g = graphify(nsg::test::draw_mask(c.truth, width_px), GraphifyOptions{});
      const double apls = nsg::test::apls(c.truth, g);
      std::printf("clean %-14s width %d px: APLS %.4f (%zu nodes)\n", c.name.c_str(), width_px, apls, g.nodes.size());
      EXPECT_GE(apls, 0.95) << c.name << " at " << width_px << " px";
      expect_undirected(g);
    }
  }
}

// Two lanes crossing (at right angles, thinned to one junction; at 45 and 30 degrees,
// thinned to two junctions a few pixels apart) graphify to two lines with no shared node;
// without the crossing rule the skeleton joins them into one piece with a 4-way (or two
// 3-way) junction and turns that no lane makes cost APLS.
TEST(Graphify, CrossingLanesBecomeTwoLinesWithNoSharedNode) {
  struct Cross {
    const char* name;
    cv::Point2d a0, a1, b0, b1;
  };
  const double r = 112.0, c = 128.0;
  auto at_deg = [&](double deg, double sign) {
    return cv::Point2d(c + sign * r * std::cos(deg * M_PI / 180), c - sign * r * std::sin(deg * M_PI / 180));
  };
  const std::vector<Cross> crosses = {{"90 deg", {16, 128}, {240, 128}, {128, 16}, {128, 240}},
                                      {"45 deg", at_deg(0, -1), at_deg(0, 1), at_deg(45, -1), at_deg(45, 1)},
                                      {"30 deg", at_deg(-15, -1), at_deg(-15, 1), at_deg(15, -1), at_deg(15, 1)}};
  for (const Cross& x : crosses) {
    nsg::metrics::Graph truth;
    nsg::test::add_line(truth, x.a0, x.a1, 7);  // 7 pieces: no node at the crossing point
    nsg::test::add_line(truth, x.b0, x.b1, 7);
    for (int width_px : {5, 7, 9}) {
      const cv::Mat mask = nsg::test::draw_mask(truth, width_px);
      const nsg::metrics::Graph g = graphify(mask, GraphifyOptions{});
      const nsg::metrics::Graph joined = graphify(mask, without_crossing_rule());
      const double apls = nsg::test::apls(truth, g), apls_joined = nsg::test::apls(truth, joined);
      std::printf("cross %-7s width %d px: APLS %.4f (without the rule %.4f)\n", x.name, width_px, apls, apls_joined);
      EXPECT_EQ(shape_of(g).pieces, 2) << x.name << " at " << width_px << " px";
      EXPECT_EQ(shape_of(g).max_degree, 2u) << x.name << " at " << width_px << " px";
      EXPECT_EQ(shape_of(joined).pieces, 1) << x.name << " at " << width_px << " px";
      EXPECT_GE(apls, 0.95) << x.name << " at " << width_px << " px";
      EXPECT_GT(apls, apls_joined) << x.name << " at " << width_px << " px";
      expect_undirected(g);
    }
  }
}

// Junctions whose branches do not pair into straight lines — a Y split, a T, a lane ending
// on another at 60 degrees — are the same with and without the crossing rule.
TEST(Graphify, SplitsAndTJunctionsAreKeptByTheCrossingRule) {
  nsg::metrics::Graph t_junction, side;
  nsg::test::add_line(t_junction, {16, 128}, {240, 128}, 8);
  nsg::test::add_line(t_junction, {128, 128}, {128, 16}, 4);
  nsg::test::add_line(side, {16, 200}, {240, 200}, 8);
  nsg::test::add_line(side, {128, 200}, {128 + 160 * 0.5, 200 - 160 * 0.866}, 6);
  const std::vector<std::pair<std::string, nsg::metrics::Graph>> cases = {
      {"y_split", nsg::test::graph_cases()[2].truth}, {"t_junction", t_junction}, {"side_60deg", side}};
  for (const auto& [name, truth] : cases) {
    for (int width_px : {5, 7, 9}) {
      const cv::Mat mask = nsg::test::draw_mask(truth, width_px);
      const nsg::metrics::Graph g = graphify(mask, GraphifyOptions{});
      const nsg::metrics::Graph kept = graphify(mask, without_crossing_rule());
      EXPECT_EQ(g.edges, kept.edges) << name << " at " << width_px << " px";
      ASSERT_EQ(g.nodes.size(), kept.nodes.size()) << name << " at " << width_px << " px";
      for (size_t k = 0; k < g.nodes.size(); ++k) {
        EXPECT_EQ(g.nodes[k].u, kept.nodes[k].u) << name;
        EXPECT_EQ(g.nodes[k].v, kept.nodes[k].v) << name;
      }
      EXPECT_EQ(shape_of(g).max_degree, 3u) << name << " at " << width_px << " px";
    }
  }
}

// The crossing rule is graphify's default and the skeleton's (so the model's) default off.
TEST(Graphify, TheCrossingRuleIsOnForGraphifyOnly) {
  EXPECT_TRUE(GraphifyOptions{}.skeleton.split_crossings);
  EXPECT_FALSE(nsg::skeleton::SkeletonOptions{}.split_crossings);
}

TEST(Graphify, AnchorsAreAtMostTwoMetresApart) {
  const nsg::metrics::Graph g = graphify(nsg::test::draw_mask(nsg::test::graph_cases()[1].truth, 7), {});
  ASSERT_FALSE(g.edges.empty());
  for (const auto& e : g.edges) {
    const auto& a = g.nodes[static_cast<size_t>(e[0])];
    const auto& b = g.nodes[static_cast<size_t>(e[1])];
    EXPECT_LE(std::hypot(b.u - a.u, b.v - a.v), 10.0 + 1e-9);  // 10 px = 2 m at 0.2 m/px
  }
}

// Probability maps: the mask blurred (σ 2 px) with peak 0.9, then 5 % of the pixels set
// to 0 or 1 at random (seeded). The measured APLS is printed; the floor is asserted.
TEST(Graphify, NoisyProbabilityMapsKeepAMeasuredFloor) {
  double sum = 0.0, worst = 1.0;
  int n = 0;
  for (const nsg::test::GraphCase& c : nsg::test::graph_cases()) {
    const cv::Mat map = nsg::test::noisy_map(nsg::test::draw_mask(c.truth, 7), 2.0, 0.9, 0.05, 43 + n);
    const nsg::metrics::Graph g = graphify(map, GraphifyOptions{});
    const double apls = nsg::test::apls(c.truth, g);
    std::printf("noisy %-14s: APLS %.4f (%zu nodes)\n", c.name.c_str(), apls, g.nodes.size());
    EXPECT_GE(apls, 0.8) << c.name;
    sum += apls;
    worst = std::min(worst, apls);
    ++n;
  }
  std::printf("noisy mean APLS %.4f, worst %.4f\n", sum / n, worst);
}

TEST(Graphify, MapKindsGiveTheSameGraph) {
  const cv::Mat mask = nsg::test::draw_mask(nsg::test::graph_cases()[2].truth, 7);
  const nsg::metrics::Graph g8 = graphify(mask, {});
  cv::Mat m01 = mask / 255, m16, mf;
  mask.convertTo(m16, CV_16U, 257.0);
  mask.convertTo(mf, CV_32F, 1.0 / 255.0);
  for (const cv::Mat& m : {m01, m16, mf}) {
    const nsg::metrics::Graph g = graphify(m, {});
    EXPECT_EQ(g.edges, g8.edges);
    ASSERT_EQ(g.nodes.size(), g8.nodes.size());
  }
  EXPECT_TRUE(graphify(cv::Mat::zeros(256, 256, CV_8U), {}).nodes.empty());
}

// Directed mode: the heading drawn along each truth edge orients every graphified edge the
// truth's way (directed APLS ≥ 0.94 — the Y split's 0.944 is its lowest, against 0.960
// undirected — no edge beside its reverse); the reversed headings
// give exactly the reversed edges; unknown headings give the undirected graph. Nodes are
// scored by the likelihood under them, edges by the mean along them (≥ 0.99 on a clean
// mask's straight lane, whose drawn edge is a pixel off the line in places).
TEST(Graphify, HeadingMapsOrientTheEdgesTheTruthsWay) {
  for (const nsg::test::GraphCase& c : nsg::test::graph_cases()) {
    const cv::Mat mask = nsg::test::draw_mask(c.truth, 7);
    const cv::Mat heading = nsg::test::draw_heading(c.truth, 7);
    const nsg::metrics::Graph g = graphify(mask, GraphifyOptions{}, c.name, &heading);
    const double apls = nsg::test::apls(c.truth, g, true);
    cv::Mat reversed = heading.clone();
    reversed.forEach<float>([](float& h, const int*) {
      if (h >= 0.0f) h = std::fmod(h + 0.5f, 1.0f);
    });
    const nsg::metrics::Graph r = graphify(mask, GraphifyOptions{}, c.name, &reversed);
    const double apls_reversed = nsg::test::apls(c.truth, r, true);
    std::printf("directed %-14s: APLS directed %.4f, reversed headings %.4f\n", c.name.c_str(), apls, apls_reversed);
    EXPECT_GE(apls, 0.94) << c.name;
    EXPECT_LT(apls_reversed, 0.5) << c.name;
    const std::set<std::array<int64_t, 2>> edges(g.edges.begin(), g.edges.end());
    for (const auto& e : g.edges) EXPECT_FALSE(edges.count({e[1], e[0]})) << c.name << ": both ways";
    ASSERT_EQ(r.edges.size(), g.edges.size()) << c.name;
    for (size_t k = 0; k < g.edges.size(); ++k)
      EXPECT_EQ(r.edges[k], (std::array<int64_t, 2>{g.edges[k][1], g.edges[k][0]})) << c.name;
    ASSERT_EQ(g.node_scores.size(), g.nodes.size());
    ASSERT_EQ(g.edge_scores.size(), g.edges.size());
    for (double v : g.node_scores) EXPECT_TRUE(v >= 0.0 && v <= 1.0) << c.name;
    for (double v : g.edge_scores) EXPECT_TRUE(v >= 0.0 && v <= 1.0) << c.name;
    if (c.name == "straight") {
      for (double v : g.node_scores) EXPECT_GE(v, 0.99);
      for (double v : g.edge_scores) EXPECT_GE(v, 0.99);
    }
    const cv::Mat unknown(mask.size(), CV_32F, cv::Scalar(-1.0f));
    const nsg::metrics::Graph u = graphify(mask, GraphifyOptions{}, c.name, &unknown);
    const nsg::metrics::Graph plain = graphify(mask, GraphifyOptions{});
    EXPECT_EQ(u.edges, plain.edges) << c.name;
    expect_undirected(u);
  }
}

// A heading map must be float32, the map's size, and hold headings in [0, 1) or negative
// values; the error names the map and the pixel.
TEST(Graphify, HeadingMapsAreChecked) {
  const cv::Mat mask = nsg::test::draw_mask(nsg::test::graph_cases()[0].truth, 7);
  auto error_of = [&](const cv::Mat& h) -> std::string {
    try {
      graphify(mask, GraphifyOptions{}, "m.png", &h);
    } catch (const nsg::DataError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  EXPECT_NE(error_of(cv::Mat(128, 256, CV_32F, cv::Scalar(0.25f))).find("the size of its map, 256 x 256 px"),
            std::string::npos);
  EXPECT_NE(error_of(cv::Mat(256, 256, CV_8U, cv::Scalar(1))).find("float32"), std::string::npos);
  cv::Mat high(256, 256, CV_32F, cv::Scalar(0.25f));
  high.at<float>(5, 7) = 1.5f;
  EXPECT_NE(error_of(high).find("m.png: heading map pixel (7, 5)"), std::string::npos) << error_of(high);
  cv::Mat nan = high.clone();
  nan.at<float>(5, 7) = NAN;
  EXPECT_NE(error_of(nan).find("pixel (7, 5)"), std::string::npos);
  EXPECT_EQ(error_of(cv::Mat(256, 256, CV_32F, cv::Scalar(0.999f))), "(accepted)");
}

TEST(Graphify, OptionsAreTheSkeletonKeysAndAreChecked) {
  std::vector<std::string> keys;
  for (const auto& s : nsg::skeleton::graphify_option_table().specs()) keys.push_back(s.key);
  EXPECT_EQ(keys,
            (std::vector<std::string>{"schema_version", "smooth_sigma_px", "threshold", "min_component_px",
                                      "min_spur_px", "simplify_tolerance_px", "anchor_spacing_px", "split_crossings",
                                      "crossing_tolerance_deg", "crossing_merge_px", "heading_window_px"}));
  GraphifyOptions bad;
  bad.skeleton.threshold = 0.0;
  EXPECT_THROW(bad.validate(), nsg::ConfigError);
  EXPECT_THROW(graphify(cv::Mat::zeros(8, 8, CV_8UC3), {}), nsg::DataError);
  EXPECT_THROW(graphify(cv::Mat::zeros(8, 8, CV_64F), {}), nsg::DataError);
  cv::Mat nan_map = cv::Mat::zeros(8, 8, CV_32F);
  nan_map.at<float>(2, 2) = NAN;
  EXPECT_THROW(graphify(nan_map, {}), nsg::DataError);
}

}  // namespace
