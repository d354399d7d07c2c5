#include "nsg/model/tile_input.h"

#include <cmath>
#include <cstring>

#include <opencv2/imgproc.hpp>

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
  if (const std::optional<graph::TileGraph> prior = tile.prior_graph()) t.prior = draw_graph_layer(*prior, size);
  return t;
}

cv::Mat draw_graph_layer(const graph::TileGraph& graph, int size_px) {
  constexpr int kShiftBits = 4;  // cv::line's fixed point: 1/16 px
  cv::Mat out = cv::Mat::zeros(size_px, size_px, CV_8U);
  const auto fixed = [](double px) { return static_cast<int>(std::lround(px * (1 << kShiftBits))); };
  for (const graph::TileEdge& e : graph.edges) {
    const graph::TileNode& a = graph.nodes[static_cast<size_t>(e.source)];
    const graph::TileNode& b = graph.nodes[static_cast<size_t>(e.target)];
    cv::line(out, {fixed(a.u_px), fixed(a.v_px)}, {fixed(b.u_px), fixed(b.v_px)}, cv::Scalar(255), 1, cv::LINE_8,
             kShiftBits);
  }
  return out;
}

}  // namespace nsg::model
