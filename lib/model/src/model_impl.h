#pragma once
// LaneModel's state, shared by training / prediction (model.cpp) and the file format
// (model_io.cpp).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/ml.hpp>

#include "nsg/model/model.h"

namespace nsg::model {

struct LaneModel::Impl {
  ModelOptions options;
  std::vector<std::string> feature_names;
  cv::Ptr<cv::ml::RTrees> centre, direction;
  cv::Ptr<cv::ml::RTrees> anchor;      // b2, graph
  cv::Ptr<cv::ml::RTrees> connection;  // graph
  nlohmann::json report;               // what training measured, kept in the file for provenance
};

}  // namespace nsg::model
