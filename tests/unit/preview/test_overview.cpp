// The e2e overview: map geometry, split region colours at known map points, LiDAR placed
// by bounds_m, crop outlines, legend.
#include <gtest/gtest.h>

#include "preview_test_util.h"

namespace nsg::test {
namespace {

preview::Overview e2e_overview(const std::string& split = "") {
  const io::Dataset ds = io::Dataset::open(e2e_dataset());
  return preview::render_overview(ds, "boston-seaport", split, {});
}

// A point of `region` at least 4 m from every crop footprint and the region's outline.
std::array<double, 2> clear_point(const std::array<double, 4>& region, const preview::Overview& ov) {
  for (double y = region[3] - 20; y > region[1] + 4; y -= 2.0)
    for (double x = region[0] + 5; x < region[2] - 4; x += 2.0) {
      bool clear = true;
      for (const auto& c : ov.crops) clear = clear && (x < c[0] - 4 || x > c[2] + 4 || y < c[1] - 4 || y > c[3] + 4);
      if (clear) return {x, y};
    }
  ADD_FAILURE() << "no clear point";
  return {region[0], region[1]};
}

TEST(Overview, RegionColoursAtKnownCoordinates) {
  const preview::Overview ov = e2e_overview();
  // manifest regions: train-west [30, 30, 110, 220], test-east [135.6, 30, 260, 220].
  ASSERT_EQ(ov.crops.size(), 17u);  // 7 train + 10 test tiles
  const auto check = [&](const std::array<double, 4>& region, const std::string& split) {
    const auto p = clear_point(region, ov);
    const auto px = ov.to_image(p[0], p[1]);
    EXPECT_EQ(ov.image.at(static_cast<int>(std::lround(px[0])), static_cast<int>(std::lround(px[1]))),
              preview::region_fill(split))
        << split << " at " << p[0] << "," << p[1];
  };
  check({30, 30, 110, 220}, "train");
  check({135.6, 30, 260, 220}, "test");
  // Between the regions (x 110 … 135.6) the map shows the plain background.
  const auto gap = ov.to_image(122.8, 100.0);
  EXPECT_EQ(ov.image.at(static_cast<int>(gap[0]), static_cast<int>(gap[1])), preview::kMapBackground);
  EXPECT_NE(preview::region_fill("train"), preview::region_fill("test"));
}

TEST(Overview, GeometryLidarAndCrops) {
  const preview::Overview ov = e2e_overview();
  // Extent 30 … 260 x 30 … 220 m padded by 5 % of 230 m; 0.2 m/px (tile resolution).
  EXPECT_DOUBLE_EQ(ov.m_per_px, 0.2);
  EXPECT_NEAR(ov.x_west_m, 30 - 11.5, 1e-9);
  EXPECT_NEAR(ov.y_north_m, 220 + 11.5, 1e-9);
  EXPECT_EQ(ov.map_rect.width, 1265);   // ceil(253 / 0.2)
  EXPECT_EQ(ov.map_rect.height, 1065);  // ceil(213 / 0.2)
  EXPECT_EQ(ov.image.width, 16 + 1265 + 16 + 260 + 16);
  // Each crop's west edge is outlined at mid-height: black, or the region outline where
  // they coincide (test-east starts at the first test crop's west edge).
  int outlined = 0, lidar = 0;
  for (const auto& c : ov.crops) {
    const int x = static_cast<int>(std::lround((c[0] - ov.x_west_m) / ov.m_per_px)) + ov.map_rect.x;
    const int y = static_cast<int>(std::lround((ov.y_north_m - (c[1] + c[3]) / 2) / ov.m_per_px)) + ov.map_rect.y;
    const preview::Rgb edge = ov.image.at(x, y);
    outlined += edge == preview::kCropOutline || edge == preview::split_color("test");
    // LiDAR shows inside crops as grey pixels (r == g == b, not the fills).
    for (int dy = 2; dy < 100; ++dy) {
      const preview::Rgb p = ov.image.at(x + 40, y - 50 + dy);
      lidar += p.r == p.g && p.g == p.b && p.r >= 64 && !(p == preview::kMapBackground);
    }
  }
  EXPECT_GE(outlined, 15);
  EXPECT_GT(lidar, 100);
  // Legend: both split regions, swatches filled.
  ASSERT_GE(ov.legend.size(), 4u);
  EXPECT_EQ(ov.legend[0].label, "train region");
  EXPECT_EQ(ov.legend[1].label, "test region");
  for (const auto& e : ov.legend) EXPECT_EQ(ov.image.at(e.swatch.x + 5, e.swatch.y + 5), e.color) << e.label;
}

TEST(Overview, SplitFilterAndUnknownLocation) {
  EXPECT_EQ(e2e_overview("train").crops.size(), 7u);
  const io::Dataset ds = io::Dataset::open(e2e_dataset());
  EXPECT_THROW(preview::render_overview(ds, "atlantis", "", {}), ConfigError);
}

}  // namespace
}  // namespace nsg::test
