#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "nsg/core/rng.h"
#include "nsg/raster/lidar_layer.h"

namespace nsg::raster {
namespace {

TEST(LidarLayer, KeepsTheLowestPointPerCell) {
  LidarLayer layer;
  const std::vector<float> a{10.05f, 20.05f, 1.5f, 200.0f, 10.15f, 20.15f, 0.1f, 12.0f};  // one cell
  layer.add_points(a.data(), 2, 4, /*sweep=*/7);
  const LidarCell* cell = layer.cells().find(cell_of(10.1, 20.1, 0.2));
  ASSERT_NE(cell, nullptr);
  EXPECT_FLOAT_EQ(cell->z, 0.1f);
  EXPECT_EQ(cell->intensity, 12);
  EXPECT_EQ(cell->sweep, 7);
  EXPECT_EQ(cell->point, 1);
  EXPECT_EQ(layer.covered_cells(), 1u);
}

// add_points bins with a multiplication and a local block table; every point must land in
// cell_of's cell (floor of the quotient) also on cell borders, at negative coordinates and
// far outside the sweep's table, and the kept point must be the lowest of its cell.
TEST(LidarLayer, BinsLikeCellOfEverywhere) {
  Rng rng(5);
  std::vector<float> pts;
  for (int i = 0; i < 20000; ++i) {
    double x = rng.uniform(-70.0, 70.0) + 1000.0, y = rng.uniform(-70.0, 70.0) - 300.0;
    if (i % 4 == 0) x = std::round(x / 0.2) * 0.2;  // on (or an ulp off) a border
    if (i % 5 == 0) y = std::round(y / 0.2) * 0.2;
    if (i % 997 == 0) x += 9000.0;  // outside the local block table
    pts.insert(pts.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(rng.uniform(-2.0, 2.0)),
                           static_cast<float>(rng.uniform(0.0, 255.0))});
  }
  LidarLayer layer;
  layer.add_points(pts.data(), pts.size() / 4, 4, 3);
  std::map<std::pair<int64_t, int64_t>, size_t> lowest;  // reference: cell → point index
  for (size_t i = 0; i < pts.size() / 4; ++i) {
    const CellIndex c = cell_of(pts[4 * i], pts[4 * i + 1], 0.2);
    auto [it, fresh] = lowest.try_emplace({c.col, c.row}, i);
    if (!fresh && pts[4 * i + 2] < pts[4 * it->second + 2]) it->second = i;
  }
  EXPECT_EQ(layer.covered_cells(), lowest.size());
  for (const auto& [key, i] : lowest) {
    const LidarCell* cell = layer.cells().find({key.first, key.second});
    ASSERT_TRUE(cell != nullptr && cell->has_data());
    ASSERT_EQ(cell->point, static_cast<int32_t>(i));
    ASSERT_EQ(cell->intensity, std::lround(pts[4 * i + 3]));
  }
}

// The column path bins against a block table kept across sweeps (recentred as the sweeps
// move) and updates cells exactly: over sweeps that wander far
// (recentring, points outside the table, blocks first seen mid-sweep), with dense repeats
// of one cell and exact height ties (decided by sweep, then point),
// every cell must equal a plain lowest-by-(z, sweep, point) reference.
TEST(LidarLayer, WanderingSweepsMatchAPlainReference) {
  Rng rng(17);
  LidarLayer layer;
  std::map<std::pair<int64_t, int64_t>, LidarCell> reference;
  for (int32_t sweep = 0; sweep < 60; ++sweep) {
    const double cx = 500.0 + 45.0 * sweep * std::cos(0.3 * sweep), cy = -200.0 + 45.0 * sweep * std::sin(0.2 * sweep);
    std::vector<float> x, y, z, intensity;
    std::vector<int32_t> ids;
    for (int i = 0; i < 3001; ++i) {
      const bool dense = i % 3 == 0;  // a 1 m patch: several points of a group share a cell
      const double r = dense ? rng.uniform(0.0, 1.0) : rng.uniform(0.0, 70.0);
      const double a = rng.uniform(0.0, 6.283185307179586);
      double px = cx + r * std::cos(a), py = cy + r * std::sin(a);
      if (i % 499 == 1) px += 3000.0;  // outside the table (centred on the first point)
      x.push_back(static_cast<float>(px));
      y.push_back(static_cast<float>(py));
      z.push_back(static_cast<float>(0.05 * static_cast<double>(rng.uniform_int(int64_t{-10}, int64_t{10}))));
      intensity.push_back(static_cast<float>(rng.uniform(0.0, 255.0)));
      ids.push_back(7 * (3001 - i));  // descending: a later point of the sweep wins a tie
    }
    layer.add_points({x.data(), y.data(), z.data(), intensity.data(), ids.data(), x.size()}, sweep);
    for (size_t i = 0; i < x.size(); ++i) {
      LidarCell cell;
      cell.x = x[i], cell.y = y[i], cell.z = z[i];
      cell.intensity = static_cast<uint8_t>(std::lround(intensity[i]));
      cell.sweep = sweep;
      cell.point = ids[i];
      const CellIndex c = cell_of(x[i], y[i], 0.2);
      auto [it, fresh] = reference.try_emplace({c.col, c.row}, cell);
      if (!fresh && cell.lower_than(it->second)) it->second = cell;
    }
  }
  ASSERT_EQ(layer.covered_cells(), reference.size());
  for (const auto& [key, want] : reference) {
    const LidarCell* got = layer.cells().find({key.first, key.second});
    ASSERT_TRUE(got != nullptr && got->has_data()) << key.first << "," << key.second;
    ASSERT_EQ(got->z, want.z);
    ASSERT_EQ(got->sweep, want.sweep);
    ASSERT_EQ(got->point, want.point);
    ASSERT_EQ(got->x, want.x);
    ASSERT_EQ(got->intensity, want.intensity);
  }
}

TEST(LidarLayer, CellsFollowFloorOfMapMetres) {
  EXPECT_EQ(cell_of(0.0, 0.0, 0.2), (CellIndex{0, 0}));
  EXPECT_EQ(cell_of(0.19999, 0.2, 0.2), (CellIndex{0, 1}));
  EXPECT_EQ(cell_of(-0.01, 5.0, 0.2), (CellIndex{-1, 25}));
}

TEST(LidarLayer, MemoryFollowsCoveredAreaNotExtent) {
  LidarLayer layer;
  // Two points 3 km apart: two blocks, not a 15 000 × 15 000 canvas.
  const std::vector<float> p{1.0f, 1.0f, 0.0f, 1.0f, 3000.0f, 3000.0f, 0.0f, 1.0f};
  layer.add_points(p.data(), 2, 4, 0);
  EXPECT_EQ(layer.cells().block_count(), 2u);
  EXPECT_LT(layer.cells().memory_bytes(), 1u << 20);
}

TEST(LidarLayer, ReductionIsOrderAndGroupingIndependent) {
  Rng rng(42);
  std::vector<std::vector<float>> sweeps(12);
  for (auto& s : sweeps)
    for (int i = 0; i < 2000; ++i) {
      s.push_back(static_cast<float>(rng.uniform(0, 20)));
      s.push_back(static_cast<float>(rng.uniform(0, 20)));
      s.push_back(static_cast<float>(rng.uniform_int(0, 3)) * 0.5f);  // many equal heights
      s.push_back(static_cast<float>(rng.uniform_int(0, 255)));
    }
  auto accumulate = [&](const std::vector<int>& order) {
    LidarLayer part;
    for (int s : order) part.add_points(sweeps[s].data(), sweeps[s].size() / 4, 4, s);
    return part;
  };
  LidarLayer all = accumulate({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11});
  LidarLayer a = accumulate({11, 3, 5, 7, 1, 9}), b = accumulate({10, 0, 8, 2, 6, 4});
  LidarLayer ba;
  ba.merge(b);
  ba.merge(a);
  size_t compared = 0;
  all.cells().for_each([&](CellIndex c, const LidarCell& x) {
    const LidarCell* y = ba.cells().find(c);
    ASSERT_NE(y, nullptr);
    EXPECT_EQ(x.z, y->z);
    EXPECT_EQ(x.sweep, y->sweep);
    EXPECT_EQ(x.point, y->point);
    compared += x.has_data();
  });
  EXPECT_EQ(compared, ba.covered_cells());
  EXPECT_GT(compared, 9000u);
}

// merge() packs the blocks it touches; sweeps added afterwards must land in
// them again (the sweep loop's block table is rebuilt) and the layer stay exact.
TEST(LidarLayer, SweepsAddedAfterAMergeLandInThePackedBlocks) {
  Rng rng(8);
  std::vector<std::vector<float>> sweeps(4);
  for (auto& s : sweeps)
    for (int i = 0; i < 3000; ++i)
      s.insert(s.end(), {static_cast<float>(rng.uniform(-15, 15)), static_cast<float>(rng.uniform(-15, 15)),
                         static_cast<float>(rng.uniform(-1, 1)), 9.0f});
  LidarLayer all, part, merged;
  for (int s = 0; s < 4; ++s) all.add_points(sweeps[s].data(), 3000, 4, s);
  part.add_points(sweeps[0].data(), 3000, 4, 0);
  merged.add_points(sweeps[1].data(), 3000, 4, 1);  // the table points at dense blocks...
  merged.merge(part);                               // ...which this packs
  merged.add_points(sweeps[2].data(), 3000, 4, 2);
  merged.add_points(sweeps[3].data(), 3000, 4, 3);
  size_t compared = 0;
  all.cells().for_each([&](CellIndex c, const LidarCell& x) {
    const LidarCell* y = merged.cells().find(c);
    ASSERT_NE(y, nullptr);
    ASSERT_EQ(x.sweep, y->sweep);
    ASSERT_EQ(x.point, y->point);
    compared += x.has_data();
  });
  EXPECT_EQ(compared, merged.covered_cells());
  EXPECT_EQ(all.covered_cells(), merged.covered_cells());
}

TEST(LidarLayer, RoofSquareAndRangeAreDropped) {
  const std::vector<float> p{0.5f,   0.9f,   0, 0, 0, 0.5f,  1.0f, 0, 0, 0,  // roof / just outside
                             -0.99f, -0.99f, 0, 0, 0, 70.0f, 0.0f, 0, 0, 0, 59.0f, 0.0f, 0, 0, 0};
  LidarOptions options;
  const std::vector<int32_t> kept = select_sweep_points(p.data(), 5, 5, options);
  EXPECT_EQ(kept, (std::vector<int32_t>{1, 4}));
}

}  // namespace
}  // namespace nsg::raster
