#pragma once
// One tile's BEV layers as OpenCV images (docs/dataset-format.md), the model's only input.
#include <string>

#include <opencv2/core.hpp>

#include "nsg/io/dataset.h"

namespace nsg::model {

struct TileInput {
  std::string key;
  cv::Mat lidar;     // CV_8U intensity, 0 = no data
  cv::Mat rgb;       // CV_8UC3 in R, G, B order; 0,0,0 = no data
  cv::Mat semantic;  // CV_8U class id, 255 = no data
  cv::Mat vehicle;   // CV_32F heading in [0, 1), −1 = no vehicle
  cv::Mat coverage;  // CV_8U bit flags: 1 LiDAR, 2 RGB, 4 semantics
  // A map-update tile's prior graph drawn 1 px wide (CV_8U, 255 on a centreline, 0 elsewhere);
  // empty when the tile has no prior graph.
  cv::Mat prior;

  int size_px() const { return lidar.rows; }
};

// Decodes the five layers of a dataset tile, and draws its prior graph when it has one;
// ParseError naming "<key>.<layer>.tif" when a layer is missing, of the wrong type or of a
// different size than the others.
TileInput tile_input_from_dataset(const io::DatasetTile& tile);

// `graph` drawn on a size_px square: every edge a 1 px line between its nodes' pixel
// positions (1/16 px precision), 255 on the line, 0 elsewhere.
cv::Mat draw_graph_layer(const graph::TileGraph& graph, int size_px);

}  // namespace nsg::model
