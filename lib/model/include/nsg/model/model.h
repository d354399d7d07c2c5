#pragma once
// The reference model: per-pixel features → random forests (OpenCV ml):
//   centreline head — regression of the centreline likelihood exp(−d²/2σ²) from the
//                     distance d to the nearest lane (the paper's B1 idea, softened);
//   LaneDirNet head — 19-class direction classifier (18 bins of 20° + background);
//   anchor head     — (b2, graph) regression of an anchor score peaked on the GT nodes;
//   connection head — (graph) has-connection classifier on anchor pairs;
// then the variant's graph building (variants.h). Trained on a CPU in minutes,
// deterministic for a seed whatever the thread count; saved as one OpenCV FileStorage
// (.yml.gz) that records the variant.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/io/dataset.h"
#include "nsg/metrics/graph.h"
#include "nsg/model/features.h"
#include "nsg/model/graph_extraction.h"
#include "nsg/model/tile_input.h"
#include "nsg/model/variants.h"

namespace nsg::model {

struct ForestOptions {
  int trees = 40;
  int max_depth = 16;
  int min_samples = 5;  // per leaf
  void validate(const std::string& field) const;
};

struct ModelOptions {
  Variant variant = Variant::kB1;
  Modalities modalities;
  ForestOptions centre{32, 14, 5};
  ForestOptions direction{40, 18, 3};
  ForestOptions anchor{24, 14, 5};      // b2, graph
  ForestOptions connection{60, 14, 3};  // graph
  AnchorOptions anchors;                // b2, graph
  PairOptions pairs;                    // graph
  double sigma_px = 2.0;                // width of the soft centreline target
  // Pixels sampled per training tile: near a centreline, around it, far from it, and for
  // the direction head on lanes plus background.
  int centre_samples_near = 200, centre_samples_around = 200, centre_samples_far = 150;
  int direction_samples_lane = 150, direction_samples_background = 30;
  // The centreline forest is evaluated every `predict_stride_px` pixels and interpolated
  // bilinearly (the likelihood is smooth at σ = 2 px; stride 2 = 4× fewer evaluations).
  int predict_stride_px = 2;
  int holdout_every = 10;  // every k-th tile (manifest order) is held out for the report; 0 = none
  uint64_t seed = 1;
  ExtractionOptions extraction;
  void validate() const;  // ConfigError naming the field
};

struct TrainReport {
  size_t tiles = 0, holdout_tiles = 0;
  size_t centre_samples = 0, direction_samples = 0;
  double features_s = 0.0, train_s = 0.0;
  // Mean squared error of the likelihood and direction-class accuracy, on the training
  // samples and on the held-out tiles' samples (lane pixels only for the direction).
  double centre_mse_train = 0.0, centre_mse_holdout = 0.0;
  double direction_accuracy_train = 0.0, direction_accuracy_holdout = 0.0;
  // b2, graph: the anchor head's MSE; graph: the connection classifier's pairs and accuracy.
  double anchor_mse_train = 0.0, anchor_mse_holdout = 0.0;
  size_t pair_samples = 0, pair_positives = 0;
  double pairs_s = 0.0;
  double pair_accuracy_train = 0.0, pair_accuracy_holdout = 0.0;
};

struct TilePrediction {
  cv::Mat likelihood;    // CV_32F centreline likelihood in [0, 1]
  cv::Mat anchor_score;  // CV_32F anchor score in [0, 1] (b2, graph; empty for b1)
  metrics::Graph graph;
};

class LaneModel {
 public:
  LaneModel();
  ~LaneModel();
  LaneModel(LaneModel&&) noexcept;
  LaneModel& operator=(LaneModel&&) noexcept;

  // Trains on every tile of `split`; progress on stderr when `progress`.
  static LaneModel train(const io::Dataset& dataset, const std::string& split, const ModelOptions& options, int threads,
                         bool progress, TrainReport* report);
  // FileStorage (.yml.gz or .yml); written to a temp name and renamed.
  void save(const std::filesystem::path& path) const;
  // ParseError naming the file when it is not a model of this format version. Files
  // without a variant (written before the variants existed) load as b1.
  static LaneModel load(const std::filesystem::path& path);
  // The same with a smaller bound on the model text, on disk or inflated, than the
  // 256 MiB kMaxModelTextBytes (the YAML parse takes ~40 ns a byte): the fuzz target's
  // inputs stay within its per-input time budget under the sanitizers.
  static LaneModel load(const std::filesystem::path& path, uint64_t max_text_bytes);

  TilePrediction predict(const TileInput& tile) const;
  const ModelOptions& options() const;

  struct Impl;  // opaque: defined in the library's sources (keeps OpenCV ml out of this header)

 private:
  std::unique_ptr<Impl> impl_;
};

// Predicts every tile of `split` (tiles in parallel; results in manifest order).
metrics::GraphSet predict_dataset(const LaneModel& model, const io::Dataset& dataset, const std::string& split,
                                  int threads, bool progress);

}  // namespace nsg::model
