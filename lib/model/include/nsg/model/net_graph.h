#pragma once
// LaneGraphNet's post-processing (the network is trained in Python, nsgraph.models; see
// docs/lanegraphnet.md): anchors from the dense anchor heatmap and its sub-pixel offset
// (what replaces the paper's region proposal network), LaneDirNet's votes at them,
// candidate pairs, the relationship head's inputs pooled from the pair-feature map, and the
// graph from the pair scores with the paper's direction rule and post-processing (shared
// with the forests). One definition: the Python predictor calls it through _nsgraph, the
// C++ ONNX predictor (onnx_net.h) directly.
#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/metrics/graph.h"
#include "nsg/model/anchors.h"
#include "nsg/model/graph_extraction.h"

namespace nsg::model {

struct NetGraphOptions {
  int stride_px = 4;                  // one output cell = stride × stride pixels
  double anchor_threshold = 0.3;      // heatmap peaks below are not anchors
  double nms_radius_px = 6.0;         // no two anchors closer (the GT spacing is ≤ 10 px)
  int vote_radius_cells = 1;          // direction votes summed over (2r + 1)² cells
  double pair_radius_px = 30.0;       // candidate pairs: anchors at most 6 m apart
  int segment_samples = 5;            // pooling points from one anchor to the other, ends included
  double min_connection_score = 0.5;  // the relationship head's decision
  // An accepted pair (a, c) is a shortcut when a third anchor b, accepted with both, lies
  // within this distance of the segment a–c (projecting inside it): the head accepts a→c
  // as well as a→b→c along one lane, and a→c would add a connection the lane does not
  // have. Shortcuts are removed (0 = off). Chosen on training tiles (docs/lanegraphnet.md).
  double shortcut_radius_px = 6.0;
  ExtractionOptions extraction = default_extraction();  // the shared post-processing
  void validate() const;                                // ConfigError naming the field

  // The paper's post-processing, with the node-score cut at the anchor threshold (node
  // scores are heatmap peaks, not centreline likelihoods).
  static ExtractionOptions default_extraction() {
    ExtractionOptions e;
    e.min_node_score = 0.3;
    return e;
  }
};

// The dense heads' outputs for one tile, each CV_32F of h × w cells.
struct NetMaps {
  cv::Mat heat;                    // anchor heatmap in [0, 1]
  cv::Mat offset_u, offset_v;      // sub-pixel offset of the anchor in its cell, in cells
  std::vector<cv::Mat> direction;  // kDirectionClasses probability maps
  std::vector<cv::Mat> features;   // the pair-feature map, one matrix per channel
  int tile_size_px = 0;
};

// Anchors (heat rounded to multiples of 1/4096 first, so runtimes that differ in the last
// bits decide alike): cells whose heat is ≥ anchor_threshold and ≥ each of its 8 neighbours, placed at
// the cell centre + offset (pixel coordinates, clamped into the tile), taken greedily by
// decreasing heat (ties: row-major) and kept when no kept anchor is within nms_radius_px,
// returned in row-major order of their cells (so tiny heat differences do not reorder them).
// Scores are the peaks' heat; votes the direction probabilities summed around the cell.
AnchorSet net_anchors(const NetMaps& maps, const NetGraphOptions& options);

// The pixel position (u, v) in cell coordinates: (u − (stride − 1)/2) / stride.
double px_to_cell(double px, int stride_px);

// Bilinear sample of a CV_32F map at cell coordinates, clamped into the map.
float sample_clamped(const cv::Mat& map, double cu, double cv);

// The relationship head's input, one CV_32F row per pair (a, b): the feature map sampled at
// segment_samples points from a to b; [f(a) + f(b), |f(a) − f(b)|, mean and max over the
// interior samples, length / pair_radius_px] — 4·C + 1 columns.
cv::Mat net_pair_inputs(const std::vector<cv::Mat>& features, const std::vector<std::array<double, 2>>& points,
                        const std::vector<std::array<int, 2>>& pairs, const NetGraphOptions& options);

// The accepted pairs without their shortcuts (see shortcut_radius_px): every pair is
// judged against the accepted set as given, so the result does not depend on its order.
// Returns a mask over `pairs`.
std::vector<bool> non_shortcut_pairs(const std::vector<std::array<double, 2>>& points,
                                     const std::vector<std::array<int, 2>>& pairs, double radius_px);

// The graph: pairs scoring ≥ min_connection_score that are not shortcuts, oriented by the
// paper's rule from the anchors' votes; node scores = anchor scores, edge scores = pair
// scores; then the shared post-processing.
metrics::Graph net_graph(const AnchorSet& anchors, const std::vector<std::array<int, 2>>& pairs,
                         const std::vector<double>& pair_scores, int tile_size_px, const NetGraphOptions& options);

}  // namespace nsg::model
