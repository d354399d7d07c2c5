// graphify on masks drawn from known lane graphs, scored against those graphs with the
// metrics library (APLS, undirected); noisy probability maps; the map readers on good and
// hostile files.
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

TEST(Graphify, OptionsAreTheSkeletonKeysAndAreChecked) {
  std::vector<std::string> keys;
  for (const auto& s : nsg::skeleton::graphify_option_table().specs()) keys.push_back(s.key);
  EXPECT_EQ(keys, (std::vector<std::string>{"schema_version", "smooth_sigma_px", "threshold", "min_component_px",
                                            "min_spur_px", "simplify_tolerance_px", "anchor_spacing_px"}));
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
