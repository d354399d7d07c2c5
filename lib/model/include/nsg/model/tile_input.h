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

  int size_px() const { return lidar.rows; }
};

// Decodes the five layers of a dataset tile; ParseError naming "<key>.<layer>.tif" when a
// layer is missing, of the wrong type or of a different size than the others.
TileInput tile_input_from_dataset(const io::DatasetTile& tile);

}  // namespace nsg::model
