#pragma once
// From a centreline likelihood map to a directed lane graph, as in the paper: threshold,
// thin, trace the skeleton into branches, place anchors at most 2 m apart along them,
// orient every edge from LaneDirNet's votes at its two anchors, then post-process (node
// score < 0.5 removed, edge score < 0.2 removed, edges longer than a quarter of the tile
// removed, isolated nodes removed).
#include <array>
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/metrics/graph.h"
#include "nsg/model/direction.h"

namespace nsg::model {

struct ExtractionOptions {
  double smooth_sigma_px = 1.0;        // Gaussian on the likelihood before thresholding (0 = none)
  double threshold = 0.5;              // likelihood that makes a pixel part of the skeleton
  int min_component_px = 20;           // smaller blobs are noise, dropped before thinning
  double min_spur_px = 6.0;            // dangling skeleton branches shorter than this are pruned
  double simplify_tolerance_px = 1.0;  // Douglas–Peucker before anchors are placed
  double anchor_spacing_px = 10.0;     // 2 m at 0.2 m/px
  // The paper's post-processing.
  double min_node_score = 0.5;
  double min_edge_score = 0.2;
  double max_edge_fraction = 0.25;  // of the tile size
  // Beyond the paper: connected pieces of the final graph shorter than this (in total edge
  // length) are fragments of clutter (crosswalk stripes, blobs in junctions) and removed.
  double min_piece_length_px = 20.0;
  // Beyond the paper: an edge more than this angle away from the mean predicted direction
  // at its anchors runs across the lanes (a skeleton bridge), not along one; removed.
  // 90 = off.
  double max_direction_angle_deg = 45.0;
  void validate() const;  // ConfigError naming the field
};

// The skeleton as branches between vertices (ends and junctions). Every branch's polyline
// starts at its first vertex's position and ends at its second's (pixel coordinates u, v).
struct SkeletonGraph {
  struct Branch {
    int a = -1, b = -1;
    std::vector<cv::Point2d> points;
  };
  std::vector<cv::Point2d> vertices;
  std::vector<Branch> branches;
};

// Bilinear sample of a CV_32F map at pixel coordinates (u, v); 0 outside the map.
double sample_bilinear(const cv::Mat& map, double u, double v);

// Zhang–Suen thinning of a binary mask (non-zero = foreground) to a one-pixel skeleton.
cv::Mat thin(const cv::Mat& mask);
// Traces a one-pixel skeleton (non-zero pixels, 8-connected). Staircase diagonals are
// treated as one path; touching junction pixels form one vertex at their mean position;
// closed loops get a vertex where they were first met.
SkeletonGraph trace_skeleton(const cv::Mat& skeleton);
// Removes dangling branches shorter than min_length_px (one pass) and unused vertices.
void prune_spurs(SkeletonGraph& graph, double min_length_px);

// Undirected anchor graph: anchors ≤ spacing apart along every simplified branch; branch
// vertices are shared anchors.
struct AnchorGraph {
  std::vector<std::array<double, 2>> nodes;  // (u, v)
  std::vector<std::array<int, 2>> pairs;     // undirected, as placed along branches
};
AnchorGraph place_anchors(const SkeletonGraph& skeleton, double spacing_px, double simplify_tolerance_px);

// LaneDirNet's class votes at anchors: for each (u, v) the votes summed over the pixels of
// a small window around it (one batched call per tile).
using Votes = std::array<float, kDirectionClasses>;
using DirectionVotes = std::function<std::vector<Votes>(const std::vector<std::array<double, 2>>& anchors)>;

// Orients every pair by the paper's rule and scores nodes (likelihood at the anchor) and
// edges (mean likelihood along the segment). `across` (optional) receives per edge the
// angle in degrees between the oriented edge and the mean predicted direction (90 when
// there is no direction evidence).
metrics::Graph orient_and_score(const AnchorGraph& anchors, const cv::Mat& likelihood, const DirectionVotes& votes,
                                std::vector<double>* angle_deg = nullptr);

// The paper's post-processing on a scored graph (node_scores and edge_scores filled).
// `angle_deg` (optional, per edge, from orient_and_score) enables max_direction_angle_deg.
void postprocess(metrics::Graph& graph, int tile_size_px, const ExtractionOptions& options,
                 const std::vector<double>* angle_deg = nullptr);

// The whole chain: likelihood (CV_32F in [0, 1]) → directed, scored, post-processed graph.
metrics::Graph extract_graph(const cv::Mat& likelihood, const DirectionVotes& votes, const ExtractionOptions& options);

}  // namespace nsg::model
