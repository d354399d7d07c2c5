#include "nsg/raster/vehicle_layer.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "nsg/core/error.h"

namespace nsg::raster {

double heading_fraction(double yaw_rad) {
  // Bearing clockwise from north: north (yaw π/2) → 0, east (yaw 0) → 0.25.
  double f = (std::numbers::pi / 2 - yaw_rad) / (2 * std::numbers::pi);
  f -= std::floor(f);
  return f >= 1.0 ? 0.0 : f;
}

bool VehicleCell::wins_over(const VehicleCell& current) const {
  return !current.has_data() || score > current.score || (score == current.score && order > current.order) ||
         (score == current.score && order == current.order && heading > current.heading);
}

void VehicleLayer::offer(CellIndex c, const VehicleCell& v, SparseGrid<VehicleCell>::Cursor& cursor) {
  VehicleCell& current = cells_.at(c, cursor);
  if (v.wins_over(current)) current = v;
}

void VehicleLayer::add_box(const VehicleBox& box) {
  const double c = std::cos(box.yaw_rad), s = std::sin(box.yaw_rad);
  const double hl = box.length_m / 2, hw = box.width_m / 2;
  const double ex = std::abs(c) * hl + std::abs(s) * hw;  // half extents of the bounding box
  const double ey = std::abs(s) * hl + std::abs(c) * hw;
  const CellIndex lo = cell_of(box.center_x_m - ex, box.center_y_m - ey, resolution_m_);
  const CellIndex hi = cell_of(box.center_x_m + ex, box.center_y_m + ey, resolution_m_);
  const VehicleCell value{static_cast<float>(heading_fraction(box.yaw_rad)), static_cast<float>(box.score), box.order};
  SparseGrid<VehicleCell>::Cursor cursor;
  for (int64_t row = lo.row; row <= hi.row; ++row) {
    for (int64_t col = lo.col; col <= hi.col; ++col) {
      const double dx = (static_cast<double>(col) + 0.5) * resolution_m_ - box.center_x_m;
      const double dy = (static_cast<double>(row) + 0.5) * resolution_m_ - box.center_y_m;
      const double along = c * dx + s * dy, across = -s * dx + c * dy;
      if (std::abs(along) <= hl && std::abs(across) <= hw) offer({col, row}, value, cursor);
    }
  }
}

void VehicleLayer::merge(const VehicleLayer& other) {
  if (other.resolution_m_ != resolution_m_)
    throw InternalError("", "", "merging vehicle layers of different resolutions");
  cells_.merge(other.cells_, [](VehicleCell& current, const VehicleCell& v) {
    if (v.wins_over(current)) current = v;
  });
}

}  // namespace nsg::raster
