// Per-pixel features on synthetic tiles whose answers are known: two painted lines 17 px
// apart (a lane between them), horizontal or vertical, a yellow line on one side, and a
// patch of vehicles heading east.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/model/features.h"
#include "nsg/model/tile_input.h"

namespace {

using nsg::model::compute_features;
using nsg::model::feature_names;
using nsg::model::FeatureMaps;
using nsg::model::Modalities;
using nsg::model::TileInput;

constexpr int kSize = 128;
// Paint on rows (or columns) 40–41 and 57–58: the lane between has its centre on row 49,
// 8 px from the nearest paint pixel on either side.
constexpr int kPaintA = 40, kPaintB = 57, kCentre = 49;

// A tile with LiDAR everywhere (asphalt intensity 20, paint 200) and no other data.
TileInput lidar_tile(bool horizontal) {
  TileInput t;
  t.key = horizontal ? "h" : "v";
  t.lidar = cv::Mat(kSize, kSize, CV_8U, cv::Scalar(20));
  for (int line : {kPaintA, kPaintB}) {
    for (int k = 0; k < 2; ++k) {
      if (horizontal) t.lidar.row(line + k).setTo(200);
      else t.lidar.col(line + k).setTo(200);
    }
  }
  t.rgb = cv::Mat::zeros(kSize, kSize, CV_8UC3);
  t.semantic = cv::Mat(kSize, kSize, CV_8U, cv::Scalar(255));
  t.vehicle = cv::Mat(kSize, kSize, CV_32F, cv::Scalar(-1.0f));
  t.coverage = cv::Mat(kSize, kSize, CV_8U, cv::Scalar(1));
  return t;
}

// Feature `name` at pixel (u, v).
float at(const FeatureMaps& f, const std::string& name, int u, int v) {
  const auto it = std::find(f.names.begin(), f.names.end(), name);
  EXPECT_NE(it, f.names.end()) << "no feature " << name;
  if (it == f.names.end()) return std::nanf("");
  return f.values.at<float>(v * kSize + u, static_cast<int>(it - f.names.begin()));
}

Modalities only_lidar() { return Modalities{true, false, false, false}; }

TEST(ModelFeatures, NamesMatchColumnsForEveryModalitySet) {
  const TileInput t = lidar_tile(true);
  for (const std::string list : {"all", "lidar", "rgb", "semantic", "vehicle", "lidar,rgb", "lidar,rgb,semantic"}) {
    const Modalities m = Modalities::parse(list);
    const FeatureMaps f = compute_features(t, m);
    EXPECT_EQ(f.names, feature_names(m)) << list;
    EXPECT_EQ(f.values.type(), CV_32F);
    EXPECT_EQ(f.values.rows, kSize * kSize) << list;
    EXPECT_EQ(f.values.cols, static_cast<int>(f.names.size())) << list;
    EXPECT_EQ(f.support.total(), static_cast<size_t>(kSize * kSize));
    // Finite everywhere: the forests cannot split on NaN.
    EXPECT_TRUE(cv::checkRange(f.values)) << list;
    // Names are unique.
    std::vector<std::string> sorted = f.names;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << list;
  }
}

TEST(ModelFeatures, SwitchingAModalityOffRemovesExactlyItsColumns) {
  const std::vector<std::string> all = feature_names(Modalities{});
  auto has_prefix = [](const std::string& n, const std::string& p) { return n.rfind(p, 0) == 0; };
  for (const std::string off : {"lidar", "rgb", "semantic", "vehicle"}) {
    Modalities m;
    if (off == "lidar") m.lidar = false;
    if (off == "rgb") m.rgb = false;
    if (off == "semantic") m.semantic = false;
    if (off == "vehicle") m.vehicle = false;
    std::vector<std::string> expected;
    for (const auto& n : all) {
      if (!has_prefix(n, off + ".")) expected.push_back(n);
    }
    EXPECT_LT(expected.size(), all.size()) << off << " has no columns in 'all'";
    EXPECT_EQ(feature_names(m), expected) << "without " << off;
  }
  // The orientation block is shared by every modality.
  const std::vector<std::string> lidar = feature_names(only_lidar());
  EXPECT_NE(std::find(lidar.begin(), lidar.end(), "orientation.cos2"), lidar.end());
  for (const auto& n : lidar) EXPECT_TRUE(has_prefix(n, "lidar.") || has_prefix(n, "orientation.")) << n;
}

TEST(ModelFeatures, ModalitiesParse) {
  EXPECT_EQ(Modalities::parse("all").to_string(), "lidar,rgb,semantic,vehicle");
  EXPECT_EQ(Modalities::parse("vehicle, lidar").to_string(), "lidar,vehicle");
  EXPECT_EQ(Modalities::parse("semantics,vehicles").to_string(), "semantic,vehicle");
  EXPECT_THROW(Modalities::parse("radar"), nsg::ConfigError);
  EXPECT_THROW(Modalities::parse("lidar,radar"), nsg::ConfigError);
  EXPECT_THROW(Modalities::parse(""), nsg::ConfigError);  // none selected
  try {
    Modalities::parse("lidar,radar");
    FAIL();
  } catch (const nsg::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("radar"), std::string::npos) << e.what();
  }
  EXPECT_THROW(compute_features(lidar_tile(true), Modalities{false, false, false, false}), nsg::ConfigError);
}

TEST(ModelFeatures, OrientationOfHorizontalAndVerticalLines) {
  // The doubled angle of a horizontal axis is 0 (cos2 = +1), of a vertical one π (−1);
  // the features are weighted by the coherence, which is ≈ 1 next to straight lines.
  for (const bool horizontal : {true, false}) {
    const FeatureMaps f = compute_features(lidar_tile(horizontal), only_lidar());
    const double sign = horizontal ? 1.0 : -1.0;
    int checked = 0;
    for (int along = 10; along < kSize - 10; along += 7) {
      for (int across : {kPaintA - 2, kPaintA, kPaintA + 3, kCentre, kPaintB + 1, kPaintB + 4}) {
        const int u = horizontal ? along : across, v = horizontal ? across : along;
        const float coherence = at(f, "orientation.coherence", u, v);
        EXPECT_GT(coherence, 0.95f) << u << "," << v;
        EXPECT_NEAR(at(f, "orientation.cos2", u, v), sign * coherence, 0.02) << u << "," << v;
        EXPECT_NEAR(at(f, "orientation.sin2", u, v), 0.0, 0.02) << u << "," << v;
        ++checked;
      }
    }
    EXPECT_GT(checked, 50);
  }
}

TEST(ModelFeatures, PaintDistanceAndProfileAcrossTheLane) {
  for (const bool horizontal : {true, false}) {
    const FeatureMaps f = compute_features(lidar_tile(horizontal), only_lidar());
    auto feature = [&](const std::string& name, int across) {
      return horizontal ? at(f, name, 64, across) : at(f, name, across, 64);
    };
    // Detected paint: exactly the four painted rows.
    for (int across = 30; across < 70; ++across) {
      const bool paint = across == kPaintA || across == kPaintA + 1 || across == kPaintB || across == kPaintB + 1;
      // lidar.paint_5 at the pixel itself is > 0 near paint only; the distance is exact.
      const int dist = std::min({std::abs(across - kPaintA), std::abs(across - kPaintA - 1), std::abs(across - kPaintB),
                                 std::abs(across - kPaintB - 1)});
      EXPECT_NEAR(feature("lidar.paint_distance", across), dist / 40.0, 1e-3) << across << (paint ? " paint" : "");
    }
    EXPECT_EQ(feature("lidar.paint_distance", kPaintA), 0.0f);
    // Midway: 8 px of asphalt to the nearest paint pixel (≈ half a 3.5 m lane at 0.2 m/px).
    EXPECT_NEAR(feature("lidar.paint_distance", kCentre), 8.0 / 40.0, 1e-3);
    EXPECT_NEAR(feature("lidar.paint_distance", kCentre + 1), 7.0 / 40.0, 1e-3);
    EXPECT_NEAR(feature("lidar.paint_distance", kCentre - 1), 7.0 / 40.0, 1e-3);
    // Paint ±8.75 px across the axis: both lines seen from the lane centre (2 rows of a
    // 5 × 5 window = 0.4 each), neither from the paint itself.
    const float centre_sum = feature("lidar.paint_across_sum_8.75", kCentre);
    EXPECT_NEAR(centre_sum, 0.8, 0.05);
    EXPECT_LT(feature("lidar.paint_across_diff_8.75", kCentre), 0.05);
    EXPECT_LT(feature("lidar.paint_across_sum_8.75", kPaintA), 0.05);
    EXPECT_LT(feature("lidar.paint_across_sum_8.75", kPaintB + 1), 0.05);
    // One line on one side only: 4 px from row 45 is paint A on one side, nothing at 8.75.
    EXPECT_LT(feature("lidar.paint_across_sum_8.75", 45), 0.5 * centre_sum);
    // Contrast: paint is brighter than its 31-px surroundings, asphalt darker.
    EXPECT_GT(feature("lidar.contrast", kPaintA), 0.3);
    EXPECT_LT(feature("lidar.contrast", kCentre), 0.0);
  }
}

TEST(ModelFeatures, YellowLineImpliesRightHandTraffic) {
  // A yellow line on rows 40–41, a white one on rows 57–58. The yellow centre line is on
  // the driver's left: the lane south of it (row 49) travels east (map +x), the lane
  // north of it (row 32) west.
  TileInput t = lidar_tile(true);
  t.rgb.setTo(cv::Scalar(60, 60, 60));
  t.rgb.rowRange(kPaintA, kPaintA + 2).setTo(cv::Scalar(230, 200, 40));
  t.rgb.rowRange(kPaintB, kPaintB + 2).setTo(cv::Scalar(240, 240, 240));
  t.coverage.setTo(1 | 2);
  const FeatureMaps f = compute_features(t, Modalities{true, true, false, false});
  for (int u : {20, 64, 100}) {
    // 8 px to the yellow line: weight exp(−8/30).
    EXPECT_NEAR(at(f, "rgb.yellow_left_dir_x", u, kCentre), std::exp(-8.0 / 30.0), 0.03) << u;
    EXPECT_NEAR(at(f, "rgb.yellow_left_dir_y", u, kCentre), 0.0, 0.03) << u;
    EXPECT_NEAR(at(f, "rgb.yellow_left_dir_x", u, 32), -std::exp(-8.0 / 30.0), 0.03) << u;
    EXPECT_NEAR(at(f, "rgb.yellow_left_dir_y", u, 32), 0.0, 0.03) << u;
    EXPECT_GT(at(f, "rgb.yellow_5", u, kPaintA), 0.35);
    EXPECT_EQ(at(f, "rgb.yellow_5", u, kCentre), 0.0f);
    EXPECT_GT(at(f, "rgb.white_5", u, kPaintB), 0.35);
    EXPECT_NEAR(at(f, "rgb.yellow_distance", u, kCentre), 8.0 / 60.0, 1e-3);
  }
}

TEST(ModelFeatures, VehicleHeadingEast) {
  // Heading 0.25 of a turn clockwise from north = east = map (+1, 0).
  TileInput t = lidar_tile(true);
  t.vehicle(cv::Rect(40, 44, 50, 12)).setTo(0.25f);
  t.vehicle(cv::Rect(40, 80, 50, 12)).setTo(0.5f);  // a second patch heading south
  const FeatureMaps f = compute_features(t, Modalities{});
  EXPECT_NEAR(at(f, "vehicle.heading_x_9", 64, 49), 1.0, 1e-5);
  EXPECT_NEAR(at(f, "vehicle.heading_y_9", 64, 49), 0.0, 1e-5);
  EXPECT_NEAR(at(f, "vehicle.heading_x_9", 64, 85), 0.0, 1e-5);
  EXPECT_NEAR(at(f, "vehicle.heading_y_9", 64, 85), -1.0, 1e-5);
  EXPECT_EQ(at(f, "vehicle.present", 64, 49), 1.0f);
  EXPECT_EQ(at(f, "vehicle.present", 10, 10), 0.0f);
  EXPECT_NEAR(at(f, "vehicle.density_9", 64, 49), 1.0, 1e-5);  // the 9 × 9 window is all vehicle
  EXPECT_EQ(at(f, "vehicle.heading_x_9", 10, 10), 0.0f);       // no vehicle nearby
}

TEST(ModelFeatures, SupportFollowsCoverage) {
  TileInput t = lidar_tile(true);
  t.coverage.setTo(0);
  t.coverage(cv::Rect(0, 0, 40, kSize)).setTo(1);  // LiDAR on the left 40 columns only
  const FeatureMaps f = compute_features(t, only_lidar());
  // features.h says "1 where …"; the implementation stores 255 (cv::Mat comparisons).
  EXPECT_NE(f.support.at<uint8_t>(64, 10), 0);
  EXPECT_EQ(f.support.at<uint8_t>(64, 100), 0);
  EXPECT_NEAR(at(f, "lidar.covered", 10, 64), 1.0, 1e-6);
  EXPECT_NEAR(at(f, "lidar.covered", 100, 64), 0.0, 1e-6);
}

// The prior modality: a map-update tile's prior graph drawn as a layer, never part of "all",
// its features measured from the drawn centreline, and named missing on a tile without one.
TEST(ModelFeatures, PriorLayerIsDrawnFromThePriorGraphAndMeasured) {
  EXPECT_EQ(Modalities::parse("all").to_string(), "lidar,rgb,semantic,vehicle");
  EXPECT_EQ(Modalities::parse("prior,all").to_string(), "lidar,rgb,semantic,vehicle,prior");
  EXPECT_EQ(Modalities::parse("prior").to_string(), "prior");
  nsg::graph::TileGraph prior;  // one lane along row 49 from column 10 to 110
  prior.nodes.resize(2);
  prior.nodes[0].u_px = 10.0;
  prior.nodes[0].v_px = 49.0;
  prior.nodes[1].u_px = 110.0;
  prior.nodes[1].v_px = 49.0;
  prior.edges.resize(1);
  prior.edges[0].source = 0;
  prior.edges[0].target = 1;
  TileInput t = lidar_tile(true);
  t.prior = nsg::model::draw_graph_layer(prior, kSize);
  EXPECT_EQ(cv::countNonZero(t.prior), 101);
  EXPECT_EQ(cv::countNonZero(t.prior.row(kCentre)), 101);
  const Modalities m = Modalities::parse("lidar,prior");
  const FeatureMaps f = compute_features(t, m);
  EXPECT_EQ(f.names, feature_names(m));
  EXPECT_EQ(at(f, "prior.distance_5", 64, kCentre), 0.0f);
  EXPECT_NEAR(at(f, "prior.distance_5", 64, kCentre + 3), 3.0 / 5.0, 1e-5);
  EXPECT_EQ(at(f, "prior.distance_20", 64, kCentre + 30), 1.0f);  // clipped
  EXPECT_NEAR(at(f, "prior.density_9", 64, kCentre), 1.0 / 9.0, 1e-6);
  const std::vector<std::string> without = feature_names(only_lidar());
  EXPECT_EQ(f.names.size(), without.size() + 4);
  t.prior.release();
  try {
    compute_features(t, m);
    FAIL() << "a tile without a prior graph";
  } catch (const nsg::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("map-update"), std::string::npos) << e.what();
  }
}

TEST(ModelFeatures, Deterministic) {
  const TileInput t = lidar_tile(false);
  const FeatureMaps a = compute_features(t, Modalities{}), b = compute_features(t, Modalities{});
  EXPECT_EQ(cv::norm(a.values, b.values, cv::NORM_INF), 0.0);
}

}  // namespace
