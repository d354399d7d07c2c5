#pragma once
// The anchor-point head shared by the b2 and graph variants (the paper's anchor proposals):
// a per-pixel anchor score learnt towards a target peaked on the ground-truth nodes, and
// anchors picked from it by non-maximum suppression no closer than the ground truth's
// node spacing.
#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/metrics/graph.h"
#include "nsg/model/graph_extraction.h"

namespace nsg::model {

struct AnchorOptions {
  // Width of the training target exp(−d²/2σ²), d = distance to the nearest GT node. At
  // 4 px (0.8 m) a point midway between two nodes 2 m apart still scores 0.46, so the
  // learnt score stays a ridge along lanes (features cannot see where along a lane the
  // GT put its nodes) while it peaks at nodes features do see (ends, junctions).
  double target_sigma_px = 4.0;
  double smooth_sigma_px = 1.0;  // Gaussian on the score map before picking
  double min_score = 0.5;        // candidates below this are not anchors (the paper's cut)
  double nms_radius_px = 10.0;   // no two anchors closer: the GT spacing, 2 m
  int neighbours = 2;            // b2: each anchor joined to this many nearest anchors
  void validate() const;         // ConfigError naming the field
};

// The anchor target at (u, v): exp(−d²/2σ²), d = distance to the nearest node of `truth`
// (0 when the graph has no node).
float anchor_target(const metrics::Graph& truth, double u, double v, double sigma_px);

// Anchors of a score map (CV_32F in [0, 1]): ridge pixels (a local maximum along at least
// two of the four axes through the pixel) scoring ≥ min_score, taken greedily by
// decreasing score (ties: row-major order) and kept when no kept anchor is within
// nms_radius_px. Pixel coordinates (u, v), in the order taken.
std::vector<std::array<double, 2>> detect_anchors(const cv::Mat& score, const AnchorOptions& options);

// Each anchor joined to its k nearest other anchors (ties: lower index), as undirected
// pairs (i < j) without duplicates, sorted.
std::vector<std::array<int, 2>> nearest_neighbour_pairs(const std::vector<std::array<double, 2>>& anchors, int k);

// What the anchor-based variants know of one tile's anchors.
struct AnchorSet {
  std::vector<std::array<double, 2>> points;    // (u, v)
  std::vector<double> scores;                   // anchor score at each point
  std::vector<Votes> votes;                     // LaneDirNet's votes around each point
  std::vector<std::array<double, 2>> mean_dir;  // mean predicted direction, pixel frame
};

// Detects the anchors of `score` and asks LaneDirNet about them (one batched call).
AnchorSet make_anchor_set(const cv::Mat& score, const DirectionVotes& votes, const AnchorOptions& options);

}  // namespace nsg::model
