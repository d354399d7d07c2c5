#pragma once
// Private to lib/raster: what LidarLayer's two sweep paths (the portable column path in
// lidar_layer.cpp, the fused AVX2 kernel in sweep_kernel_avx2.cpp) share, so both decide
// every cell the same way.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

#include "nsg/raster/lidar_layer.h"

namespace nsg::raster {

namespace sweep_kernel {

static_assert(kBlockCells == 64, "the binning uses shifts and masks of 64");

// The block table: kTableBlocks² block pointers (±16 blocks = ±204 m at 0.2 m) centred
// near the sweeps; recentred when a sweep starts more than kRecentreBlocks from the
// centre, so a sweep (≤ 60 m ≈ 5 blocks around its sensor) stays inside. Points outside
// the table go through the map.
inline constexpr int64_t kTableBlocks = 32;
inline constexpr int64_t kRecentreBlocks = 6;
// The table has one more entry, always null: the slot of points that cannot be screened.
inline constexpr int32_t kNullSlot = static_cast<int32_t>(kTableBlocks * kTableBlocks);

// Inf and NaN have every exponent bit set.
inline constexpr uint32_t kFloatExponent = 0x7f800000u;

// The first of `rows` rows of 5 float32 holding an Inf or NaN, or −1.
inline int64_t first_non_finite_row(const float* rows5, size_t rows) {
  for (size_t i = 0; i < 5 * rows; ++i)
    if ((std::bit_cast<uint32_t>(rows5[i]) & kFloatExponent) == kFloatExponent) return static_cast<int64_t>(i / 5);
  return -1;
}

// The vector screens work on int32 block coordinates: a table origin beyond ±2^30 blocks
// (±1.4e10 m at 0.2 m) only loses the screen, never correctness.
inline bool table_fits_int32(int64_t bx0, int64_t by0) {
  return std::abs(bx0) < (int64_t{1} << 30) && std::abs(by0) < (int64_t{1} << 30);
}

}  // namespace sweep_kernel

// `exact` = col/row came from the vector binning (floor of x·(1/res)) and the value was
// far enough from a cell border for that to equal cell_of; otherwise cell_of decides.
inline void LidarLayer::update_cell(const PointRef& p, int64_t col, int64_t row, bool exact, int32_t sweep_id,
                                    SparseGrid<LidarCell>::Cursor& cursor) {
  using sweep_kernel::kTableBlocks;
  if (!exact) [[unlikely]] {
    const CellIndex c = cell_of(p.x, p.y, resolution_m_);
    col = c.col;
    row = c.row;
  }
  const uint64_t tx = static_cast<uint64_t>((col >> 6) - table_.bx0);
  const uint64_t ty = static_cast<uint64_t>((row >> 6) - table_.by0);
  LidarCell* current;
  float* z_copy;  // the table's z copy of the cell, or a sink outside the table
  float sink;
  if ((tx | ty) < static_cast<uint64_t>(kTableBlocks)) [[likely]] {
    const size_t slot = ty * kTableBlocks + tx;
    if (table_.cells[slot] == nullptr) [[unlikely]]
      attach_block(slot, col >> 6, row >> 6);
    const size_t offset = static_cast<size_t>(((row & 63) << 6) | (col & 63));
    current = table_.cells[slot] + offset;
    z_copy = table_.z[slot] + offset;
  } else {
    current = &cells_.at({col, row}, cursor);
    z_copy = &sink;
  }
  offer_point(p, sweep_id, *current, *z_copy);
}

inline void LidarLayer::offer_point(const PointRef& p, int32_t sweep_id, LidarCell& current, float& z_copy) {
  // Most points are not lower than what the cell holds (an empty cell's z is +inf):
  // decide on z before building; equal heights go on to the full tie-break.
  if (p.z > current.z) return;
  LidarCell cell;
  cell.x = p.x;
  cell.y = p.y;
  cell.z = p.z;
  // = clamp(lround(intensity), 0, 255) without the libm call (exact in double).
  cell.intensity = static_cast<uint8_t>(std::clamp(static_cast<double>(p.intensity), 0.0, 255.0) + 0.5);
  cell.sweep = sweep_id;
  cell.point = p.point;
  if (!current.has_data() || cell.lower_than(current)) {
    covered_cells_ += !current.has_data();
    current = cell;
    z_copy = cell.z;
  }
}

}  // namespace nsg::raster
