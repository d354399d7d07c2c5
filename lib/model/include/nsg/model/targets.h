#pragma once
// Per-pixel training targets from a tile's ground-truth graph, by the paper's adaptive
// ground truth: every pixel centre is projected orthogonally onto its nearest lane segment
// (graph::SegmentIndex); the projection gives the distance to the centreline and the
// travel direction there.
#include <opencv2/core.hpp>

#include "nsg/metrics/graph.h"

namespace nsg::model {

struct TileTargets {
  cv::Mat distance_px;  // CV_32F, to the nearest segment; max_distance_px where none is nearer
  cv::Mat angle_rad;    // CV_32F, map angle of that segment's direction; NaN where none
};

TileTargets compute_targets(const metrics::Graph& truth, int size_px, double max_distance_px);

}  // namespace nsg::model
