// The fused AVX2 sweep kernel (LidarLayer::add_sweep, SweepPath::kFused) against the
// portable column path and against a plain reference built from the scalar pieces
// (select_sweep_points, transform_points_devkit twice, cell_of, LidarCell::lower_than):
// identical layers, field by field and bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "nsg/geometry/transform.h"
#include "nsg/raster/lidar_layer.h"

namespace nsg::raster {
namespace {

using geometry::Quaternion;
using geometry::Rigid3;
using Path = LidarLayer::SweepPath;

struct Sweep {
  std::vector<float> rows;  // 5 float32 per point, sensor frame
  Rigid3 ego_from_sensor, global_from_ego;
  int32_t id = 0;
  size_t count() const { return rows.size() / 5; }
};

Quaternion random_rotation(Rng& rng) {
  Quaternion q{rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)};
  return q;  // not unit: rotation_matrix normalises, as pyquaternion does
}

// Sweeps that exercise every branch of the kernel: roof-square points and its edge
// (|x| = 1 m), points beyond 60 m and on the range circle, dense patches (several points
// of one group of 8 in one cell), heights on a 5 cm grid with yaw-only rotations so equal
// global z happen (ties resolved by sweep, then point: the sweep ids descend, so a later
// sweep wins a tie), cell-border coordinates (identity rotations, x on k·0.2 and an ulp
// off), points outside the block table (a sensor 500 m from the ego), counts that are not
// multiples of 8 or of the kernel's chunk, and a pose too far out for int32 cells.
std::vector<Sweep> random_sweeps(uint64_t seed) {
  Rng rng(seed);
  std::vector<Sweep> sweeps;
  for (int s = 0; s < 48; ++s) {
    Sweep sw;
    sw.id = 1000 - 7 * s;
    const int kind = s % 6;  // 0,1: yaw only; 2: identity + borders; 3: full 3-D; 4: far sensor; 5: huge pose
    const double yaw = rng.uniform(-3.2, 3.2);
    const Quaternion ego_rot =
        kind == 2 ? Quaternion{} : (kind == 3 ? random_rotation(rng) : geometry::quaternion_from_yaw(yaw));
    const Quaternion sensor_rot =
        kind == 2 ? Quaternion{}
                  : (kind == 3 ? random_rotation(rng) : geometry::quaternion_from_yaw(-std::numbers::pi / 2));
    const std::array<double, 3> sensor_t =
        kind == 4 ? std::array<double, 3>{500.0, -20.0, 1.8} : std::array<double, 3>{0.94, 0.0, 1.84};
    const double ex = kind == 5 ? 3.1e8 : 600.0 + 9.0 * s + rng.uniform(0.0, 1.0);
    const double ey = kind == 5 ? -2.0e8 : 1100.0 - 4.0 * s + rng.uniform(0.0, 1.0);
    sw.ego_from_sensor = Rigid3::from_pose(sensor_t, sensor_rot);
    sw.global_from_ego = Rigid3::from_pose({ex, ey, 0.25}, ego_rot);  // one height: ties across sweeps
    const int n = 1500 + static_cast<int>(rng.uniform_int(int64_t{0}, int64_t{1700}));
    for (int i = 0; i < n; ++i) {
      double x, y;
      const int what = static_cast<int>(rng.uniform_int(int64_t{0}, int64_t{9}));
      if (what == 0) {  // roof square (and its edges)
        x = rng.uniform(-1.2, 1.2), y = rng.uniform(-1.2, 1.2);
        if (i % 3 == 0) x = i % 2 ? 1.0 : -1.0;
      } else if (what == 1) {  // beyond range, or on the circle
        const double a = rng.uniform(0.0, 6.3), r = i % 2 ? rng.uniform(59.0, 90.0) : 60.0;
        x = r * std::cos(a), y = r * std::sin(a);
      } else if (what <= 4) {  // a dense 0.6 m patch
        x = 7.0 + rng.uniform(0.0, 0.6), y = -3.0 + rng.uniform(0.0, 0.6);
      } else {
        const double a = rng.uniform(0.0, 6.3), r = rng.uniform(0.0, 62.0);
        x = r * std::cos(a), y = r * std::sin(a);
      }
      float fx = static_cast<float>(x), fy = static_cast<float>(y);
      if (kind == 2 && i % 2 == 0) {  // global x/y on a cell border (or an ulp off it)
        fx = static_cast<float>(std::round((x + ex) / 0.2) * 0.2 - ex);
        fy = static_cast<float>(std::round((y + ey) / 0.2) * 0.2 - ey);
        if (i % 4 == 0) fx = std::nextafter(fx, i % 8 == 0 ? 1e9f : -1e9f);
      }
      const float z = static_cast<float>(0.05 * static_cast<double>(rng.uniform_int(int64_t{-20}, int64_t{20})));
      sw.rows.insert(sw.rows.end(),
                     {fx, fy, z, static_cast<float>(rng.uniform(-10.0, 300.0)), static_cast<float>(i % 32)});
    }
    sweeps.push_back(std::move(sw));
  }
  return sweeps;
}

// Each sweep in one call, or in runs of `run_rows` rows (as the sweep loop reads them).
LidarLayer accumulate(const std::vector<Sweep>& sweeps, Path path, std::vector<size_t>& kept,
                      size_t run_rows = SIZE_MAX) {
  LidarLayer layer;
  for (const Sweep& s : sweeps) {
    size_t n = 0;
    for (size_t first = 0; first < s.count(); first += run_rows) {
      const size_t count = std::min(run_rows, s.count() - first);
      n += layer.add_sweep(s.rows.data() + 5 * first, count, static_cast<int32_t>(first), s.ego_from_sensor,
                           s.global_from_ego, LidarOptions{}, s.id, path);
    }
    kept.push_back(n);
  }
  return layer;
}

uint32_t bits(float v) { return std::bit_cast<uint32_t>(v); }

void expect_same_cell(const LidarCell& got, const LidarCell& want, CellIndex c) {
  ASSERT_EQ(bits(got.z), bits(want.z)) << c.col << "," << c.row;
  ASSERT_EQ(bits(got.x), bits(want.x)) << c.col << "," << c.row;
  ASSERT_EQ(bits(got.y), bits(want.y)) << c.col << "," << c.row;
  ASSERT_EQ(got.intensity, want.intensity) << c.col << "," << c.row;
  ASSERT_EQ(got.sweep, want.sweep) << c.col << "," << c.row;
  ASSERT_EQ(got.point, want.point) << c.col << "," << c.row;
}

TEST(SweepKernel, FusedEqualsPortableFieldByField) {
  if (!LidarLayer::fused_kernel_available()) GTEST_SKIP() << "optional hardware: no AVX2 on this CPU";
  for (uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<Sweep> sweeps = random_sweeps(seed);
    std::vector<size_t> kept_portable;
    const LidarLayer portable = accumulate(sweeps, Path::kPortable, kept_portable);
    for (Path path : {Path::kFused, Path::kFusedAvx2}) {  // AVX-512 transforms where the CPU has them; AVX2 only
      std::vector<size_t> kept_fused;
      const LidarLayer fused = accumulate(sweeps, path, kept_fused);
      EXPECT_EQ(kept_fused, kept_portable);
      ASSERT_EQ(fused.cells().block_count(), portable.cells().block_count());
      ASSERT_EQ(fused.covered_cells(), portable.covered_cells());
      ASSERT_GT(portable.covered_cells(), 20000u);
      size_t compared = 0;
      portable.cells().for_each([&](CellIndex c, const LidarCell& want) {
        const LidarCell* got = fused.cells().find(c);
        ASSERT_NE(got, nullptr);
        expect_same_cell(*got, want, c);
        compared += want.has_data();
      });
      EXPECT_EQ(compared, portable.covered_cells());
    }
  }
}

// The plain reference: select_sweep_points, then transform_points_devkit twice on float32
// rows, then cell_of and lower_than per point.
TEST(SweepKernel, BothPathsEqualAPlainReference) {
  const std::vector<Sweep> sweeps = random_sweeps(9);
  std::map<std::pair<int64_t, int64_t>, LidarCell> reference;
  size_t ties = 0, cross_sweep_ties = 0;
  for (const Sweep& s : sweeps) {
    const std::vector<int32_t> kept = select_sweep_points(s.rows.data(), s.count(), 5, LidarOptions{});
    std::vector<float> xyz;
    for (int32_t i : kept) xyz.insert(xyz.end(), {s.rows[5 * i], s.rows[5 * i + 1], s.rows[5 * i + 2]});
    geometry::transform_points_devkit(s.ego_from_sensor, xyz.data(), kept.size(), 3);
    geometry::transform_points_devkit(s.global_from_ego, xyz.data(), kept.size(), 3);
    for (size_t j = 0; j < kept.size(); ++j) {
      LidarCell cell;
      cell.x = xyz[3 * j], cell.y = xyz[3 * j + 1], cell.z = xyz[3 * j + 2];
      cell.intensity = static_cast<uint8_t>(std::lround(std::clamp(s.rows[5 * kept[j] + 3], 0.0f, 255.0f)));
      cell.sweep = s.id;
      cell.point = kept[j];
      const CellIndex c = cell_of(cell.x, cell.y, 0.2);
      auto [it, fresh] = reference.try_emplace({c.col, c.row}, cell);
      if (fresh) continue;
      ties += it->second.z == cell.z;
      cross_sweep_ties += it->second.z == cell.z && it->second.sweep != cell.sweep;
      if (cell.lower_than(it->second)) it->second = cell;
    }
  }
  EXPECT_GT(ties, 500u);  // the tie rule is exercised
  // Whole sweeps, and runs of 333 rows (not a multiple of 8: runs end mid-group; the cells
  // must still name each point by its row in the whole sweep).
  for (const auto& [path, run_rows] : {std::pair{Path::kPortable, SIZE_MAX}, std::pair{Path::kPortable, size_t{333}},
                                       std::pair{Path::kFused, SIZE_MAX}, std::pair{Path::kFused, size_t{333}},
                                       std::pair{Path::kFusedAvx2, SIZE_MAX}}) {
    if (path != Path::kPortable && !LidarLayer::fused_kernel_available()) continue;
    SCOPED_TRACE("path " + std::to_string(static_cast<int>(path)) + ", runs of " + std::to_string(run_rows));
    std::vector<size_t> kept;
    const LidarLayer layer = accumulate(sweeps, path, kept, run_rows);
    ASSERT_EQ(layer.covered_cells(), reference.size());
    for (const auto& [key, want] : reference) {
      const LidarCell* got = layer.cells().find({key.first, key.second});
      ASSERT_TRUE(got != nullptr && got->has_data()) << key.first << "," << key.second;
      expect_same_cell(*got, want, {key.first, key.second});
    }
  }
}

// Random data almost never tells (a + b) + c from a + (b + c) once rounded to float32
// (≈ 1e-9 of points), so a crafted matrix makes each row's products 1 + 2^-24 (a float32
// tie), 2^-53 and 2^-53: the devkit order gives exactly the tie (→ 1.0f, to even), any
// other grouping 1 + 2^-24 + 2^-52 (→ 1 + 2^-23). A translation added in float64 before
// the rounding, or no rounding between the two transforms, also changes the bits.
TEST(SweepKernel, KeepsTheDevkitOrderOfOperations) {
  Rigid3 crafted;
  crafted.rotation << 1.0 + 0x1p-24, 0x1p-53, 0x1p-53, 1.0 + 0x1p-24, 0x1p-53, 0x1p-53, 1.0 + 0x1p-24, 0x1p-53, 0x1p-53;
  Rigid3 shift;  // a translation that is not a float32: rounded first, then added in float32
  shift.translation = Eigen::Vector3d(1179.4673290964536, -3.0000001, 0.30000001);
  std::vector<float> rows;
  for (int i = 0; i < 19; ++i) {                       // two full groups of 8 and a tail
    const float v = static_cast<float>(1 << (i % 4));  // 1, 2, 4, 8: the tie at each scale
    rows.insert(rows.end(), {v, v, v, 10.0f, 0.0f});
  }
  std::vector<float> xyz;
  for (size_t i = 0; i < rows.size() / 5; ++i) xyz.insert(xyz.end(), {rows[5 * i], rows[5 * i + 1], rows[5 * i + 2]});
  geometry::transform_points_devkit(crafted, xyz.data(), xyz.size() / 3, 3);
  geometry::transform_points_devkit(shift, xyz.data(), xyz.size() / 3, 3);
  for (Path path : {Path::kPortable, Path::kFused, Path::kFusedAvx2}) {
    if (path != Path::kPortable && !LidarLayer::fused_kernel_available()) continue;
    LidarLayer layer;
    ASSERT_EQ(layer.add_sweep(rows.data(), rows.size() / 5, 0, crafted, shift, LidarOptions{}, 4, path), 19u);
    for (size_t i = 0; i < 4; ++i) {  // the first point of each scale keeps its cell (lowest id on a tie)
      const LidarCell* cell = layer.cells().find(cell_of(xyz[3 * i], xyz[3 * i + 1], 0.2));
      ASSERT_NE(cell, nullptr);
      EXPECT_EQ(bits(cell->x), bits(xyz[3 * i])) << "path " << static_cast<int>(path) << ", point " << i;
      EXPECT_EQ(bits(cell->y), bits(xyz[3 * i + 1])) << "path " << static_cast<int>(path) << ", point " << i;
      EXPECT_EQ(bits(cell->z), bits(xyz[3 * i + 2])) << "path " << static_cast<int>(path) << ", point " << i;
      EXPECT_EQ(cell->point, static_cast<int32_t>(i));
    }
  }
}

TEST(SweepKernel, EmptyAndTinySweeps) {
  const Rigid3 identity;
  for (Path path : {Path::kPortable, Path::kFused, Path::kFusedAvx2}) {
    if (path != Path::kPortable && !LidarLayer::fused_kernel_available()) continue;
    LidarLayer layer;
    EXPECT_EQ(layer.add_sweep(nullptr, 0, 0, identity, identity, LidarOptions{}, 1, path), 0u);
    // Three rows (no full group of 8): roof, kept, beyond range.
    const std::vector<float> rows{0.5f,  0.5f, 0.0f,  9.0f, 0.0f, 10.1f, 4.1f, -1.5f,
                                  77.6f, 3.0f, 70.0f, 0.0f, 0.0f, 1.0f,  0.0f};
    EXPECT_EQ(layer.add_sweep(rows.data(), 3, 0, identity, identity, LidarOptions{}, 2, path), 1u);
    const LidarCell* cell = layer.cells().find(cell_of(10.1, 4.1, 0.2));
    ASSERT_NE(cell, nullptr);
    EXPECT_EQ(cell->z, -1.5f);
    EXPECT_EQ(cell->intensity, 78);
    EXPECT_EQ(cell->point, 1);
    EXPECT_EQ(layer.covered_cells(), 1u);
  }
}

// The AVX-512 stage A decides the filter in float32 where that is exact: with a roof and
// a range that are not float32 values, points one ulp either side of the roof edge and of
// the range circle must be kept or dropped as the float64 test does.
TEST(SweepKernel, FilterEdgesWithOddOptions) {
  LidarOptions odd;
  odd.roof_half_size_m = 1.05;
  odd.max_range_m = 47.3;
  std::vector<float> rows;
  auto add = [&](float x, float y) {
    rows.insert(rows.end(), {x, y, -0.01f * static_cast<float>(rows.size() / 5), 7.0f, 0.0f});
  };
  // First, points where a plain float32 test of x² + y² > range² gets it wrong (found by a
  // scan; only the margins make the kernel take float64 for them).
  const double range2 = odd.max_range_m * odd.max_range_m;
  size_t misjudged = 0;
  for (int a = 0; a < 20000 && misjudged < 12; ++a) {
    const double angle = 0.00157 * a;
    const float cy = static_cast<float>(odd.max_range_m * std::sin(angle));
    float x = static_cast<float>(odd.max_range_m * std::cos(angle));
    for (int k = 0; k < 4; ++k) x = std::nextafter(x, 0.0f);
    for (int k = 0; k < 9; ++k, x = std::nextafter(x, 1e9f)) {
      const float s32 = x * x + cy * cy;
      const double s64 = static_cast<double>(x) * x + static_cast<double>(cy) * cy;
      const float range2_32 = static_cast<float>(range2);
      if (s32 != range2_32 && (s32 > range2_32) != (s64 > range2)) add(x, cy), ++misjudged;
    }
  }
  ASSERT_GE(misjudged, 4u);
  while (rows.size() / 5 % 16 != 0) add(20.0f, -20.0f);  // their own groups of 16: no other lane forces float64
  const float roof = static_cast<float>(odd.roof_half_size_m);
  for (float edge : {roof, -roof}) {
    float x = edge;
    for (int k = 0; k < 4; ++k) x = std::nextafter(x, 0.0f);
    for (int k = 0; k < 9; ++k, x = std::nextafter(x, edge * 2)) add(x, 0.5f), add(0.25f, x);
  }
  for (int a = 0; a < 24; ++a) {  // around the range circle, a few ulps either side
    const double angle = 0.2618 * a;
    const float cx = static_cast<float>(odd.max_range_m * std::cos(angle));
    const float cy = static_cast<float>(odd.max_range_m * std::sin(angle));
    for (int k = -2; k <= 2; ++k) {
      float x = cx;
      for (int step = 0; step < std::abs(k); ++step) x = std::nextafter(x, k > 0 ? 1e9f : -1e9f);
      add(x, cy);
    }
  }
  while (rows.size() / 5 % 16 != 5) add(20.0f, -20.0f);  // whole groups of 16 and a tail
  const size_t n = rows.size() / 5;
  std::vector<int32_t> expected = select_sweep_points(rows.data(), n, 5, odd);
  ASSERT_GT(expected.size(), 20u);
  ASSERT_LT(expected.size(), n - 20);
  for (Path path : {Path::kPortable, Path::kFused, Path::kFusedAvx2}) {
    if (path != Path::kPortable && !LidarLayer::fused_kernel_available()) continue;
    LidarLayer layer;
    EXPECT_EQ(layer.add_sweep(rows.data(), n, 0, Rigid3{}, Rigid3{}, odd, 3, path), expected.size())
        << "path " << static_cast<int>(path);
  }
}

// The finite check done in the kernel's pass (the reader skips its own): the first row with
// an Inf or NaN in any of its five values, wherever it falls (a group of 8 or 16, a group's
// first or last row, the tail, a later kernel chunk), as a file row.
TEST(SweepKernel, FindsTheFirstNonFiniteRow) {
  constexpr size_t kRows = 5003;  // three kernel chunks, the last ending in a tail
  constexpr int32_t kFirstRow = 100;
  Rng rng(5);
  std::vector<float> clean;
  for (size_t i = 0; i < kRows; ++i)
    clean.insert(clean.end(),
                 {static_cast<float>(rng.uniform(-50.0, 50.0)), static_cast<float>(rng.uniform(-50.0, 50.0)),
                  static_cast<float>(rng.uniform(-2.0, 2.0)), 9.0f, static_cast<float>(i % 32)});
  const Rigid3 pose = Rigid3::from_pose({600.0, 1100.0, 0.3}, geometry::quaternion_from_yaw(0.4));
  const float bad_values[] = {std::nanf(""), std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity()};
  for (Path path : {Path::kPortable, Path::kFused, Path::kFusedAvx2}) {
    if (path != Path::kPortable && !LidarLayer::fused_kernel_available()) continue;
    SCOPED_TRACE("path " + std::to_string(static_cast<int>(path)));
    int64_t bad_row = 7;
    LidarLayer clean_layer;
    const size_t kept =
        clean_layer.add_sweep(clean.data(), kRows, kFirstRow, Rigid3{}, pose, LidarOptions{}, 1, path, &bad_row);
    EXPECT_EQ(bad_row, -1);
    EXPECT_GT(kept, kRows / 2);
    size_t k = 0;
    for (size_t row : {size_t{0}, size_t{7}, size_t{8}, size_t{15}, size_t{16}, size_t{2047}, size_t{2048},
                       size_t{3001}, kRows - 2, kRows - 1}) {
      std::vector<float> rows = clean;
      const size_t column = k % 5;  // x, y, z, intensity and ring in turn
      rows[5 * row + column] = bad_values[k % 3];
      if (row + 40 < kRows) rows[5 * (row + 40) + 1] = std::nanf("");  // a later one is not the first
      ++k;
      LidarLayer layer;
      layer.add_sweep(rows.data(), kRows, kFirstRow, Rigid3{}, pose, LidarOptions{}, 1, path, &bad_row);
      EXPECT_EQ(bad_row, kFirstRow + static_cast<int64_t>(row)) << "row " << row << ", column " << column;
      LidarLayer thrown;  // without the out-parameter: an error naming the point
      try {
        thrown.add_sweep(rows.data(), kRows, kFirstRow, Rigid3{}, pose, LidarOptions{}, 1, path);
        ADD_FAILURE() << "no error for row " << row;
      } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("point " + std::to_string(kFirstRow + row)), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("finite"), std::string::npos) << e.what();
      }
    }
  }
}

TEST(SweepKernel, RowsBeyondInt32IndicesAreRefused) {
  LidarLayer layer;
  const std::vector<float> rows(10, 1.0f);
  EXPECT_THROW(layer.add_sweep(rows.data(), 2, INT32_MAX - 1, Rigid3{}, Rigid3{}, LidarOptions{}, 1), InternalError);
  EXPECT_THROW(layer.add_sweep(rows.data(), 2, -1, Rigid3{}, Rigid3{}, LidarOptions{}, 1), InternalError);
  EXPECT_EQ(layer.add_sweep(rows.data(), 1, INT32_MAX - 1, Rigid3{}, Rigid3{}, LidarOptions{}, 1), 1u);
  EXPECT_EQ(layer.cells().find(cell_of(1.0, 1.0, 0.2))->point, INT32_MAX - 1);
}

}  // namespace
}  // namespace nsg::raster
