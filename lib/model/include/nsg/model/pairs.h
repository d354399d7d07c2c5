#pragma once
// The graph variant's has-connection relation (the paper's LaneGraphNet idea on light
// learners): candidate anchor pairs within a radius, their features, and their training
// labels from the adaptive ground truth (graph::project_onto_lanes, the paper's §III-C).
#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/graph/lane_graph.h"
#include "nsg/metrics/graph.h"
#include "nsg/model/anchors.h"

namespace nsg::model {

struct PairOptions {
  double radius_px = 30.0;            // candidate pairs: anchors at most 6 m apart
  double min_connection_score = 0.5;  // the classifier's decision: below, no edge
  // Adaptive ground truth: anchors farther than this from every GT lane are not projected
  // (their pairs are negatives); connectivity followed this far through lanes without anchors.
  double label_max_distance_px = 10.0;
  double label_max_follow_px = 100.0;
  // Training pairs come from every k-th training tile (the classifier needs far fewer
  // samples than the pixel heads, and each tile costs a full prediction); splits of fewer
  // than 30·k tiles use a smaller k, down to every tile.
  int train_tile_every = 4;
  void validate() const;  // ConfigError naming the field
};

// Unordered anchor pairs (i < j) at most radius_px apart, sorted.
std::vector<std::array<int, 2>> candidate_pairs(const std::vector<std::array<double, 2>>& anchors, double radius_px);

// Names of the pair features, one per column of pair_features.
std::vector<std::string> pair_feature_names();
// One CV_32F row per pair: length, anchor scores at both ends, the centreline likelihood
// and anchor score sampled along the segment, the angle between the segment and the
// predicted lane direction at both ends, the two ends' direction agreement and
// confidence, each end's neighbour rank of the other, and the anchors the segment skips.
// Symmetric in the two ends (min / max), since direction comes from LaneDirNet later.
cv::Mat pair_features(const AnchorSet& anchors, const std::vector<std::array<int, 2>>& pairs, const cv::Mat& likelihood,
                      const cv::Mat& anchor_score);

// A tile's ground-truth graph as lanes for the projection: maximal chains between nodes
// that are not simple pass-throughs (in = out = 1), successors across shared end nodes,
// coordinates in pixels (x_m = u, y_m = v).
graph::LaneGraph lane_graph_from_tile(const metrics::Graph& truth);

// 1 where the adaptive ground truth connects the pair's anchors (either direction), else 0.
std::vector<int> connection_labels(const metrics::Graph& truth, const std::vector<std::array<double, 2>>& anchors,
                                   const std::vector<std::array<int, 2>>& pairs, const PairOptions& options);

}  // namespace nsg::model
