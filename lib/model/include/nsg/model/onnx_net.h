#pragma once
// LaneGraphNet exported to ONNX (python -m nsgraph.models.export), run with OpenCV's dnn:
// <name>.onnx holds the dense heads (inputs lidar, rgb, semantic, vehicle; outputs heat,
// offset, direction, features), <name>.pairs.onnx next to it the relationship head
// (input pairs (N, 4·C + 1), output P(has-connection) (N, 1)). The post-processing is
// net_graph.h's, the same the Python predictor calls.
#include <filesystem>
#include <memory>
#include <string>

#include "nsg/io/dataset.h"
#include "nsg/metrics/graph.h"
#include "nsg/model/net_graph.h"
#include "nsg/model/tile_input.h"

namespace nsg::model {

// The network's inputs from a tile's layers, as NCHW float blobs (1, C, H, W):
// lidar (intensity / 255, presence), rgb (/ 255), semantic (one-hot of the 14 classes,
// no data = all zero), vehicle (sin and cos of 2π·heading, presence; 0 without a vehicle).
// nsgraph.models.lanegraphnet.encode_inputs is its Python twin.
struct NetInputs {
  cv::Mat lidar, rgb, semantic, vehicle;
};
NetInputs encode_net_inputs(const TileInput& tile);

class OnnxLaneNet {
 public:
  // Loads <path> and <path without .onnx>.pairs.onnx; ParseError naming the file when
  // OpenCV dnn cannot load one, IoError when one is missing.
  static OnnxLaneNet load(const std::filesystem::path& dense_onnx, const NetGraphOptions& options = {});
  OnnxLaneNet(OnnxLaneNet&&) noexcept;
  ~OnnxLaneNet();

  // The dense heads' maps of one tile (size a multiple of 64 px; DataError naming the key
  // otherwise).
  NetMaps dense(const TileInput& tile);
  // P(has-connection) per row of net_pair_inputs.
  std::vector<double> pair_scores(const cv::Mat& pair_inputs);
  // The whole chain for one tile.
  metrics::Graph predict(const TileInput& tile);

 private:
  struct Impl;
  explicit OnnxLaneNet(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Every tile of a split, in manifest order (one network; OpenCV's own threads: `threads`).
metrics::GraphSet predict_dataset_onnx(const std::filesystem::path& dense_onnx, const io::Dataset& dataset,
                                       const std::string& split, int threads, bool progress);

}  // namespace nsg::model
