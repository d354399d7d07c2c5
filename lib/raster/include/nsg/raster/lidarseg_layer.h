#pragma once
// The semantic layer from nuScenes-lidarseg (camera.semantic_source "lidarseg"): every
// labelled point of the key-frame LIDAR_TOP sweeps, filtered and moved to the global frame
// exactly like the LiDAR layer's points, binned at the same resolution; a cell takes the
// class of its lowest point whose label maps to one of our classes (a point whose label
// maps to void — noise, the ego, classes we lack — is not "labelled" and never wins).
// Lowest-wins with the (z, sweep, point) order of LidarCell, so the result depends
// neither on sweep order nor on thread count.
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "nsg/nuscenes/token.h"
#include "nsg/raster/color_layer.h"
#include "nsg/raster/lidar_layer.h"
#include "nsg/raster/sparse_grid.h"

namespace nsg::nuscenes {
class Database;
}

namespace nsg::raster {

// Our class id (samples/semantic-classes.json) of each lidarseg label; 255 = void.
using LidarsegClassTable = std::array<uint8_t, 256>;

struct LidarsegCell {
  float z = std::numeric_limits<float>::infinity();
  int32_t sweep = -1, point = -1;
  uint8_t cls = 255;
  bool has_data() const { return sweep >= 0; }
  bool lower_than(const LidarsegCell& o) const { return lower_point(*this, o); }
};

struct LidarsegStats {
  size_t sweeps = 0;                 // key-frame sweeps of the scenes
  size_t sweeps_without_labels = 0;  // of those, without a lidarseg record (e.g. the test split)
  size_t points_labelled = 0;        // kept points (roof and range filters) with a class
  size_t cells = 0;                  // cells with a class
};

struct LidarsegLayer {
  SparseGrid<LidarsegCell> cells;  // packed: the labelled cells only
  LidarsegStats stats;
};

// Reads lidarseg.json and the labels of the key-frame `lidar_channel` sweeps of `scenes`
// (scene-table rows of one location). Throws IoError naming lidarseg.json when it is
// missing, DataError naming a label file whose size is not the sweep's point count, and
// the sweep reader's errors.
LidarsegLayer accumulate_lidarseg(const nuscenes::Database& db, const std::vector<nuscenes::Index>& scenes,
                                  const LidarOptions& lidar, const std::string& lidar_channel,
                                  const LidarsegClassTable& classes, int threads);

// Puts the lidarseg classes of the cells inside `regions` (empty = all) into `color` as
// its semantic layer (flag kCoverageSemantic), leaving RGB as it is.
void overlay_semantics(ColorLayer& color, const LidarsegLayer& lidarseg, const std::vector<CellRect>& regions);

}  // namespace nsg::raster
