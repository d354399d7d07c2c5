#pragma once
// Per-pixel features of a tile for the reference model: local means at several scales,
// marking densities and distances, the orientation of structures (structure tensor),
// profiles of markings across that orientation, and vehicle headings — each modality
// switchable so the paper's ablation rows can be reproduced.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/model/tile_input.h"

namespace nsg::model {

struct Modalities {
  bool lidar = true;
  bool rgb = true;
  bool semantic = true;
  bool vehicle = true;
  // A map-update tile's prior map, drawn as a layer (TileInput::prior): an input the sensors
  // do not give, so never part of "all"; a model trained with it needs map-update tiles.
  bool prior = false;

  // "lidar,rgb,semantic,vehicle,prior" (any subset, any order; "all" = the four sensor
  // layers); ConfigError otherwise.
  static Modalities parse(const std::string& list);
  std::string to_string() const;  // canonical order, e.g. "lidar,rgb"
  bool any() const { return lidar || rgb || semantic || vehicle || prior; }
  void validate() const;  // at least one
};

struct FeatureMaps {
  std::vector<std::string> names;  // one per column
  cv::Mat values;                  // CV_32F, rows = pixels in row-major order, cols = names
  cv::Mat support;                 // CV_8U per pixel: non-zero where an enabled layer has data nearby
};

// Feature names for a modality set (the columns compute_features returns, in order).
std::vector<std::string> feature_names(const Modalities& modalities);

// All features of every pixel. Deterministic; cost ≈ a few ms per 256-px tile.
FeatureMaps compute_features(const TileInput& tile, const Modalities& modalities);

}  // namespace nsg::model
