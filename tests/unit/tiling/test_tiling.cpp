// Split regions and crop sampling on LiDAR layers whose coverage is known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "nsg/core/error.h"
#include "nsg/raster/lidar_layer.h"
#include "nsg/tiling/crops.h"
#include "nsg/tiling/regions.h"

namespace nsg::tiling {
namespace {

constexpr double kRes = 0.2;

// A layer with one point in every cell of [x0, x1) × [y0, y1) (metres).
raster::LidarLayer filled(double x0, double y0, double x1, double y1) {
  raster::LidarLayer layer(kRes);
  std::vector<float> pts;
  for (double y = y0 + kRes / 2; y < y1; y += kRes)
    for (double x = x0 + kRes / 2; x < x1; x += kRes) pts.insert(pts.end(), {float(x), float(y), 0.0f, 10.0f});
  layer.add_points(pts.data(), pts.size() / 4, 4, 0);
  return layer;
}

TEST(Crops, WindowCoverageCountsCellsExactly) {
  const raster::LidarLayer layer = filled(0, 0, 25.6, 51.2);  // the west half of a 256-px window
  EXPECT_DOUBLE_EQ(window_coverage(layer, 0, 0, 256), 0.5);
  EXPECT_DOUBLE_EQ(window_coverage(layer, -64, 0, 256), 0.5);  // window straddles negative blocks
  EXPECT_DOUBLE_EQ(window_coverage(layer, 128, 0, 256), 0.0);
  EXPECT_DOUBLE_EQ(window_coverage(layer, 0, 0, 128), 1.0);
  EXPECT_EQ(covered_cells_in(layer, {0, 0, 10, 10}), 50 * 50);
}

TEST(Regions, CoveredWindowBoundsTheCellsHoldingPoints) {
  const CellWindow w = covered_window(filled(-12.8, 0, 25.6, 51.2));
  EXPECT_EQ(w.col0, -64);
  EXPECT_EQ(w.row0, 0);
  EXPECT_EQ(w.col1, 128);
  EXPECT_EQ(w.row1, 256);
  EXPECT_TRUE(covered_window(raster::LidarLayer(kRes)).empty());
}

TEST(Crops, GridCropsTileTheRegionAndRespectTheThreshold) {
  const raster::LidarLayer layer = filled(0, 0, 160, 100);
  CropOptions o;
  o.size_px = 100;  // 20 m
  o.min_lidar_coverage = 0.5;
  const std::vector<Region> regions = {{"t", "test", {0, 0, 200, 100}}};
  const std::vector<Crop> crops = plan_crops(layer, regions, o, 1);
  // 10 columns × 5 rows fit; columns at x ≥ 160 have no LiDAR.
  EXPECT_EQ(crops.size(), 8u * 5u);
  std::set<std::pair<int64_t, int64_t>> corners;
  for (const Crop& c : crops) {
    EXPECT_TRUE(regions[0].bounds.contains(c.bounds(kRes, o.size_px)));
    EXPECT_EQ(c.col0 % 100, 0);
    EXPECT_DOUBLE_EQ(c.lidar_coverage, 1.0);
    EXPECT_TRUE(corners.insert({c.col0, c.row0}).second) << "grid crops never repeat";
  }
}

TEST(Crops, RandomCropsAreSeededInsideTheRegionAndAboveThreshold) {
  const raster::LidarLayer layer = filled(0, 0, 100, 100);
  CropOptions o;
  o.size_px = 50;
  o.random_total = 30;
  const std::vector<Region> regions = {{"r", "train", {10, 10, 130, 90}}};
  const std::vector<Crop> a = plan_crops(layer, regions, o, 7), b = plan_crops(layer, regions, o, 7),
                          c = plan_crops(layer, regions, o, 8);
  ASSERT_EQ(a.size(), 30u);
  bool differs = false;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].col0, b[i].col0);
    EXPECT_EQ(a[i].row0, b[i].row0);
    differs |= a[i].col0 != c[i].col0 || a[i].row0 != c[i].row0;
    EXPECT_TRUE(regions[0].bounds.contains(a[i].bounds(kRes, o.size_px)));
    EXPECT_GE(a[i].lidar_coverage, o.min_lidar_coverage);
  }
  EXPECT_TRUE(differs) << "another seed gives other crops";
}

TEST(Regions, AutomaticBlocksKeepSplitsOneBufferApartAndFollowRatios) {
  const raster::LidarLayer layer = filled(0, 0, 800, 800);
  SplitOptions o;
  o.block_size_m = 160;
  o.ratios = {0.6, 0.1, 0.3};
  const std::vector<Region> regions = plan_regions(layer, o, 51.2, 3);
  std::map<std::string, int> n;
  for (const Region& r : regions) ++n[r.split];
  // 25 blocks: round(25·0.3) = 8 test, round(25·0.1) = 3 val (half away from zero); train blocks that lost too
  // much to buffers on both sides may be dropped.
  EXPECT_EQ(n["test"], 8);
  EXPECT_EQ(n["val"], 3);
  EXPECT_GT(n["train"], 5);
  EXPECT_GE(min_split_gap_m(regions), o.buffer_m - 1e-9);
  const std::vector<Region> again = plan_regions(layer, o, 51.2, 3);
  ASSERT_EQ(again.size(), regions.size());
  for (size_t i = 0; i < regions.size(); ++i) EXPECT_EQ(again[i].name, regions[i].name);
}

TEST(Regions, ExplicitRegionsAreCheckedForTheBuffer) {
  const raster::LidarLayer layer = filled(0, 0, 10, 10);
  SplitOptions o;
  o.regions = {{"a", "train", {0, 0, 100, 100}}, {"b", "test", {120, 0, 220, 100}}};
  EXPECT_THROW(o.validate(51.2), ConfigError);  // 20 m apart < 51.2 m
  o.regions[1].bounds = {151.2, 0, 251.2, 100};
  EXPECT_EQ(plan_regions(layer, o, 51.2, 1).size(), 2u);
  o.regions[1].split = "holdout";
  EXPECT_THROW(o.validate(51.2), ConfigError);
}

// The planners count what each filter took (generate's empty-dataset message reads them).
TEST(Crops, StatsCountEveryCandidateWindow) {
  const raster::LidarLayer layer = filled(0, 0, 150, 100);
  CropOptions o;
  o.size_px = 100;  // 20 m
  o.min_lidar_coverage = 0.6;
  const std::vector<Region> regions = {{"t", "test", {0, 0, 200, 100}}, {"small", "test", {300, 0, 319.9, 100}}};
  CropStats st;
  const std::vector<Crop> crops = plan_crops(layer, regions, o, 1, &st);
  const SplitCropStats& test = st.splits[2];
  EXPECT_EQ(test.regions, 2);
  EXPECT_EQ(test.regions_no_room, 1) << "19.9 m is narrower than a 20 m crop";
  // 10 × 5 grid windows: columns 0–6 full, column 7 (x 140–160) half covered (< 0.6), 8–9 empty.
  EXPECT_EQ(test.windows, 50);
  EXPECT_EQ(test.kept, 35);
  EXPECT_EQ(test.below_coverage, 15);
  EXPECT_EQ(static_cast<size_t>(test.kept), crops.size());
  EXPECT_DOUBLE_EQ(test.best_rejected_coverage, 0.5);
  EXPECT_NEAR(test.covered_km2, 150.0 * 100.0 * 1e-6, 1e-9);
  EXPECT_EQ(st.splits[0].windows, 0);

  // Random placement: a region whose share rounds to 0 crops asks for none.
  o.random_per_km2 = 10.0;  // × 0.015 km² = 0.15 → 0
  const std::vector<Region> train = {{"r", "train", {0, 0, 150, 100}}};
  EXPECT_TRUE(plan_crops(layer, train, o, 1, &st).empty());
  EXPECT_EQ(st.splits[0].regions, 1);
  EXPECT_EQ(st.splits[0].regions_none_wanted, 1);
  EXPECT_EQ(st.splits[0].windows, 0);
  EXPECT_EQ(st.splits[2].regions, 0) << "the stats are reset per call";
  o.random_per_km2 = 1000.0;  // 15 wanted
  o.min_lidar_coverage = 1.0;
  const std::vector<Crop> some = plan_crops(layer, train, o, 1, &st);
  EXPECT_EQ(st.splits[0].wanted, 15);
  EXPECT_EQ(st.splits[0].windows, st.splits[0].kept + st.splits[0].below_coverage);
  EXPECT_EQ(static_cast<size_t>(st.splits[0].kept), some.size());
}

TEST(Regions, StatsCountBlocksPerSplit) {
  SplitOptions o;
  o.block_size_m = 160;
  o.ratios = {0.6, 0.1, 0.3};
  RegionStats st;
  const std::vector<Region> regions = plan_regions(filled(0, 0, 800, 800), o, 51.2, 3, &st);
  EXPECT_FALSE(st.explicit_regions);
  EXPECT_FALSE(st.no_lidar);
  EXPECT_DOUBLE_EQ(st.block_size_m, 160.0);
  EXPECT_EQ(st.blocks, 25);
  EXPECT_EQ(st.blocks_low_coverage, 0);
  EXPECT_EQ(st.blocks_assigned[0], 14);
  EXPECT_EQ(st.blocks_assigned[1], 3);
  EXPECT_EQ(st.blocks_assigned[2], 8);
  EXPECT_EQ(static_cast<size_t>(25 - st.blocks_too_small[0] - st.blocks_too_small[1] - st.blocks_too_small[2]),
            regions.size());

  // Only one corner block holds LiDAR: the other blocks fall below min_block_coverage.
  o.block_size_m = 0;
  raster::LidarLayer corner = filled(0, 0, 40, 40);
  const float far[] = {399.9f, 399.9f, 0.0f, 1.0f};
  corner.add_points(far, 1, 4, 0);
  EXPECT_EQ(plan_regions(corner, o, 51.2, 3, &st).size(), 1u);
  EXPECT_EQ(st.blocks, 16);
  EXPECT_EQ(st.blocks_low_coverage, 15);
  EXPECT_EQ(st.blocks_assigned[2], 0) << "one block: no test block";

  EXPECT_TRUE(plan_regions(raster::LidarLayer(kRes), o, 51.2, 3, &st).empty());
  EXPECT_TRUE(st.no_lidar);
  o.regions = {{"a", "train", {0, 0, 100, 100}}};
  plan_regions(corner, o, 51.2, 3, &st);
  EXPECT_TRUE(st.explicit_regions);
  EXPECT_EQ(st.blocks, 0);
}

}  // namespace
}  // namespace nsg::tiling
