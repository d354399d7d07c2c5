#pragma once
// The bits of a tile's coverage.tif (docs/dataset-format.md), declared once: set where a layer
// has data. The rasters set them, io::tile_members() names them per layer, validate checks
// them, the previews and the report draw them.
#include <cstdint>

namespace nsg {

inline constexpr uint8_t kCoverageLidar = 1;     // lidar.tif has an intensity
inline constexpr uint8_t kCoverageRgb = 2;       // rgb.tif has a camera colour
inline constexpr uint8_t kCoverageSemantic = 4;  // semantic.tif has a class
// Every valid flag value is a subset of these.
inline constexpr uint8_t kCoverageAll = kCoverageLidar | kCoverageRgb | kCoverageSemantic;

}  // namespace nsg
