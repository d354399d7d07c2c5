#pragma once
// The paper's adaptive ground truth: arbitrary points (anchor proposals of a model) are
// projected orthogonally onto their nearest lane segment, ordered along each lane, and
// consecutive projections are labelled connected — along a lane and across connectivity.
#include <cstdint>
#include <utility>
#include <vector>

#include "nsg/graph/lane_graph.h"
#include "nsg/graph/segment_index.h"

namespace nsg::graph {

struct ProjectionOptions {
  double max_distance_m = 4.0;  // points farther from every lane are not projected
  double max_follow_m = 20.0;   // how far connectivity is followed through lanes without points
  void validate() const;
};

struct ProjectedPoint {
  int32_t input = -1;  // index of the input point
  int32_t lane = -1;   // lane index in the graph
  int32_t edge = -1;   // edge index in the graph
  double x_m = 0.0, y_m = 0.0;
  double along_lane_m = 0.0;  // arc length from the lane's start to the projection
  double distance_m = 0.0;    // from the input point
};

struct AdaptiveGroundTruth {
  std::vector<ProjectedPoint> points;                    // projected inputs, ordered by lane then along the lane
  std::vector<std::pair<int32_t, int32_t>> connections;  // directed, indices into points
  // Lateral links, apart from the connections (a lane change is no successor): for each of
  // the graph's lane changes s → t, the point nearest node s among those on an edge at s,
  // to the point nearest t among those on an edge at t; sorted, each pair once.
  std::vector<std::pair<int32_t, int32_t>> lane_changes;

  // Whether points[a] → points[b] is a connection.
  bool has_connection(int32_t a, int32_t b) const;
};

AdaptiveGroundTruth project_onto_lanes(const LaneGraph& graph, const SegmentIndex& index,
                                       const std::vector<Node>& points, const ProjectionOptions& options);

}  // namespace nsg::graph
