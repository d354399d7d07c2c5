#pragma once
// The members of a tile (docs/dataset-format.md), declared once: the writer, `validate`, `inspect
// layers`, `preview` and the Python package (nsgraph.LAYERS) read this list instead of
// restating names, files, dtypes, no-data values and coverage bits.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "nsg/io/raster.h"

namespace nsg::io {

struct TileMember {
  std::string name;    // "lidar"; the file is <key>.<file>
  std::string file;    // "lidar.tif"
  bool raster = true;  // GeoTIFF; else JSON
  SampleType dtype = SampleType::kUInt8;
  int bands = 1;
  std::string unit;              // what a value means
  std::optional<double> nodata;  // the no-data value (GDAL_NODATA tag); none for coverage and JSON
  uint8_t coverage_bit = 0;      // the bit of coverage.tif set where this layer has data; 0 = none
  std::string description;
};

// Every member of a complete tile, in the order the writer emits them.
const std::vector<TileMember>& tile_members();
// The raster members (lidar, rgb, semantic, vehicle, coverage), in member order.
std::vector<const TileMember*> raster_members();
// The member called `name` ("lidar") or with file `name` ("lidar.tif"); nullptr if none.
const TileMember* find_tile_member(std::string_view name);
const char* dtype_name(SampleType type);  // "uint8", "float32"

}  // namespace nsg::io
