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

void LidarLayer::add_points(const float* xyzi, size_t count, size_t stride, int32_t sweep_id,
                            const int32_t* point_ids) {
  SparseGrid<LidarCell>::Cursor cursor;
  for (size_t i = 0; i < count; ++i) {
    const float* p = xyzi + i * stride;
    LidarCell cell;
    cell.x = p[0];
    cell.y = p[1];
    cell.z = p[2];
    cell.intensity = static_cast<uint8_t>(std::clamp(std::lround(p[3]), 0L, 255L));
    cell.sweep = sweep_id;
    cell.point = point_ids ? point_ids[i] : static_cast<int32_t>(i);
    LidarCell& current = cells_.at(cell_of(p[0], p[1], resolution_m_), cursor);
    if (!current.has_data() || cell.lower_than(current)) current = cell;
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
