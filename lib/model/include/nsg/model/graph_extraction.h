#pragma once
// From a centreline likelihood map to a directed lane graph, as in the paper: threshold,
// thin, trace the skeleton into branches, place anchors at most 2 m apart along them
// (nsg::skeleton, nsg/skeleton/skeleton.h),
// orient every edge from LaneDirNet's votes at its two anchors, then post-process (node
// score < 0.5 removed, edge score < 0.2 removed, edges longer than a quarter of the tile
// removed, isolated nodes removed).
#include <array>
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/metrics/graph.h"
#include "nsg/model/direction.h"
#include "nsg/skeleton/skeleton.h"

namespace nsg::model {

// The skeleton's parameters (extraction.smooth_sigma_px … anchor_spacing_px, declared
// once in nsg::skeleton) and the post-processing's.
struct ExtractionOptions : skeleton::SkeletonOptions {
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

// The skeleton chain lives in nsg::skeleton (shared with `nsgraph graphify`); its names
// are the model's too.
using skeleton::AnchorGraph;
using skeleton::place_anchors;
using skeleton::prune_spurs;
using skeleton::sample_bilinear;
using skeleton::SkeletonGraph;
using skeleton::thin;
using skeleton::trace_skeleton;

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
