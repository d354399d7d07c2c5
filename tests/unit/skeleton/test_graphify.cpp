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
  EXPECT_EQ(keys, (std::vector<std::string>{"schema_version", "smooth_sigma_px", "threshold", "min_component_px",
                                            "min_spur_px", "simplify_tolerance_px", "anchor_spacing_px",
                                            "heading_window_px"}));
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
