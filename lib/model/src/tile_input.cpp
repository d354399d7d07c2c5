#include "nsg/model/tile_input.h"

#include <cstring>

#include "nsg/core/error.h"

namespace nsg::model {
namespace {

// A decoded raster as a cv::Mat of the expected type and size; ParseError otherwise.
cv::Mat layer(const io::DatasetTile& tile, const std::string& suffix, io::SampleType type, int bands, int cv_type,
              int size_px) {
  const io::Raster r = tile.raster(suffix);
  const std::string name = tile.key + "." + suffix;
  NSG_CHECK(r.type == type && r.bands == bands, ParseError, name, "layer",
            std::to_string(bands) + " band(s) of the layer's sample type (docs/dataset-format.md)");
  NSG_CHECK(r.width == r.height && (size_px < 0 || r.width == size_px), ParseError, name, "size",
            "a square raster of the tile's size");
  cv::Mat m(r.height, r.width, cv_type);
  std::memcpy(m.data, r.data.data(), r.expected_bytes());
  return m;
}

}  // namespace

TileInput tile_input_from_dataset(const io::DatasetTile& tile) {
  TileInput t;
  t.key = tile.key;
  t.lidar = layer(tile, "lidar.tif", io::SampleType::kUInt8, 1, CV_8U, -1);
  const int size = t.lidar.rows;
  t.rgb = layer(tile, "rgb.tif", io::SampleType::kUInt8, 3, CV_8UC3, size);
  t.semantic = layer(tile, "semantic.tif", io::SampleType::kUInt8, 1, CV_8U, size);
  t.vehicle = layer(tile, "vehicle.tif", io::SampleType::kFloat32, 1, CV_32F, size);
  t.coverage = layer(tile, "coverage.tif", io::SampleType::kUInt8, 1, CV_8U, size);
  return t;
}

}  // namespace nsg::model
