#pragma once
// The vehicle layer (docs/architecture.md): each box footprint filled with its heading
// = clockwise bearing of the box's forward axis from map north (+y) / 2π, in [0, 1);
// −1 where no box. Overlaps: the higher score wins, then the later `order` (annotations
// use score 1 and the key-frame order, so the latest key frame wins).
#include <cstdint>
#include <vector>

#include "nsg/raster/sparse_grid.h"

namespace nsg::raster {

struct VehicleBox {
  double center_x_m = 0.0;
  double center_y_m = 0.0;
  double yaw_rad = 0.0;   // heading of the box's forward (length) axis, CCW from +x
  double length_m = 0.0;  // along the forward axis
  double width_m = 0.0;
  double score = 1.0;
  int64_t order = 0;  // tie-break: larger wins (e.g. key-frame timestamp)
};

struct VehicleCell {
  float heading = -1.0f;  // −1 = no vehicle
  float score = -1.0f;
  int64_t order = -1;

  bool has_data() const { return heading >= 0.0f; }
  // The overlap rule: a higher score, then a later order, then a larger heading (so the
  // result does not depend on the order boxes and layers come in).
  bool wins_over(const VehicleCell& current) const;
};

// Heading in [0, 1) of a forward axis with yaw `yaw_rad` (CCW from east).
double heading_fraction(double yaw_rad);

class VehicleLayer {
 public:
  explicit VehicleLayer(double resolution_m = 0.2) : resolution_m_(resolution_m) {}
  // Fills every cell whose centre lies inside the box footprint.
  void add_box(const VehicleBox& box);
  // Order-free union (the overlap rule); leaves the blocks it touches packed.
  void merge(const VehicleLayer& other);
  // Empties the layer, keeping its storage for the next boxes.
  void clear() { cells_.clear(); }
  const SparseGrid<VehicleCell>& cells() const { return cells_; }

 private:
  void offer(CellIndex c, const VehicleCell& v, SparseGrid<VehicleCell>::Cursor& cursor);
  double resolution_m_;
  SparseGrid<VehicleCell> cells_;
};

}  // namespace nsg::raster
