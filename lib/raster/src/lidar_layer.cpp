#include "nsg/raster/lidar_layer.h"

#include <algorithm>
#include <cmath>

#include "nsg/core/error.h"

namespace nsg::raster {

void LidarOptions::validate() const {
  if (!(resolution_m > 0.0)) throw ConfigError("", "lidar.resolution_m", "expected > 0 m");
  if (!(roof_half_size_m >= 0.0)) throw ConfigError("", "lidar.roof_half_size_m", "expected ≥ 0 m");
  if (!(max_range_m > 0.0)) throw ConfigError("", "lidar.max_range_m", "expected > 0 m");
}

std::vector<int32_t> select_sweep_points(const float* points, size_t count, size_t stride,
                                         const LidarOptions& options) {
  std::vector<int32_t> kept;
  kept.reserve(count);
  const double roof = options.roof_half_size_m;
  const double range2 = options.max_range_m * options.max_range_m;
  for (size_t i = 0; i < count; ++i) {
    const double x = points[i * stride], y = points[i * stride + 1];
    if (std::abs(x) < roof && std::abs(y) < roof) continue;  // a square, like remove_close
    if (x * x + y * y > range2) continue;
    kept.push_back(static_cast<int32_t>(i));
  }
  return kept;
}

void LidarLayer::offer(CellIndex c, const LidarCell& cell) {
  LidarCell& current = cells_.at(c);
  if (!current.has_data() || cell.lower_than(current)) current = cell;
}

namespace {

// floor(x / res) exactly as cell_of computes it, but with a multiplication by 1/res (the
// two divisions per point cost more than the rest of the binning): the product differs
// from the quotient by a few ulps (< 1e-6 of a cell below 1e9 cells), so only a value
// that close to a cell border, or beyond, is redone by cell_of's division.
inline bool fast_cell(double x_m, double y_m, double inv_res, int64_t& col, int64_t& row) {
  const double qx = x_m * inv_res, qy = y_m * inv_res;
  if (!(std::abs(qx) < 1e9 && std::abs(qy) < 1e9)) return false;
  col = static_cast<int64_t>(qx);
  row = static_cast<int64_t>(qy);
  col -= static_cast<double>(col) > qx;
  row -= static_cast<double>(row) > qy;
  const double rx = qx - static_cast<double>(col), ry = qy - static_cast<double>(row);
  return rx >= 1e-6 && rx <= 1.0 - 1e-6 && ry >= 1e-6 && ry <= 1.0 - 1e-6;
}

static_assert(kBlockCells == 64, "add_points bins with shifts and masks of 64");

// The sweep's local block table: kTableBlocks² block pointers centred on the block of
// the sweep's first point (±16 blocks = ±204 m at 0.2 m, beyond any sweep's range), so a
// point finds its block without a map lookup; points outside go through the map.
constexpr int64_t kTableBlocks = 32;
thread_local std::vector<LidarCell*> block_table;

}  // namespace

void LidarLayer::add_points(const float* xyzi, size_t count, size_t stride, int32_t sweep_id,
                            const int32_t* point_ids) {
  if (count == 0) return;
  const double inv_res = 1.0 / resolution_m_;
  const CellIndex first = cell_of(xyzi[0], xyzi[1], resolution_m_);
  const int64_t bx0 = SparseGrid<LidarCell>::floor_div(first.col) - kTableBlocks / 2;
  const int64_t by0 = SparseGrid<LidarCell>::floor_div(first.row) - kTableBlocks / 2;
  block_table.assign(kTableBlocks * kTableBlocks, nullptr);
  SparseGrid<LidarCell>::Cursor cursor;  // for points outside the table
  for (size_t i = 0; i < count; ++i) {
    const float* p = xyzi + i * stride;
    int64_t col, row;
    if (!fast_cell(p[0], p[1], inv_res, col, row)) [[unlikely]] {
      const CellIndex c = cell_of(p[0], p[1], resolution_m_);
      col = c.col;
      row = c.row;
    }
    const uint64_t tx = static_cast<uint64_t>((col >> 6) - bx0), ty = static_cast<uint64_t>((row >> 6) - by0);
    LidarCell* current;
    if ((tx | ty) < static_cast<uint64_t>(kTableBlocks)) [[likely]] {
      LidarCell*& block = block_table[ty * kTableBlocks + tx];
      if (block == nullptr) [[unlikely]]
        block = cells_.block_data(col >> 6, row >> 6);
      current = block + (((row & 63) << 6) | (col & 63));
    } else {
      current = &cells_.at({col, row}, cursor);
    }
    // Most points are not lower than what the cell holds: decide on z before building.
    if (current->has_data() && p[2] > current->z) continue;
    LidarCell cell;
    cell.x = p[0];
    cell.y = p[1];
    cell.z = p[2];
    // = clamp(lround(intensity), 0, 255) without the libm call (exact in double).
    cell.intensity = static_cast<uint8_t>(std::clamp(static_cast<double>(p[3]), 0.0, 255.0) + 0.5);
    cell.sweep = sweep_id;
    cell.point = point_ids ? point_ids[i] : static_cast<int32_t>(i);
    if (!current->has_data() || cell.lower_than(*current)) *current = cell;
  }
}

void LidarLayer::merge(const LidarLayer& other) {
  if (other.resolution_m_ != resolution_m_)
    throw InternalError("", "", "merging LiDAR layers of different resolutions");
  other.cells_.for_each([&](CellIndex c, const LidarCell& cell) {
    if (cell.has_data()) offer(c, cell);
  });
}

size_t LidarLayer::covered_cells() const {
  size_t n = 0;
  cells_.for_each([&](CellIndex, const LidarCell& cell) { n += cell.has_data(); });
  return n;
}

}  // namespace nsg::raster
