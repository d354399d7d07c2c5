#pragma once
// A uniform grid over the edges of a lane graph: which edges pass near a box, which edge
// is nearest to a point. Memory grows with the number of edges, not the map canvas
// (cells are hashed, only occupied ones exist).
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "nsg/graph/lane_graph.h"

namespace nsg::graph {

struct NearestEdge {
  int32_t edge = -1;  // −1 when nothing within the search radius
  double distance_m = 0.0;
  double t = 0.0;               // position on the edge, 0 = source, 1 = target
  double x_m = 0.0, y_m = 0.0;  // the closest point
};

class SegmentIndex {
 public:
  explicit SegmentIndex(const LaneGraph& graph, double cell_m = 8.0);

  // Edge indices whose bounding box meets [x_min, x_max] × [y_min, y_max], ascending.
  std::vector<int32_t> query_box(double x_min, double y_min, double x_max, double y_max) const;
  // The edge nearest to (x, y) within max_distance_m; ties go to the smallest edge index.
  NearestEdge nearest(double x_m, double y_m, double max_distance_m) const;

 private:
  int64_t key(int64_t cx, int64_t cy) const { return (cx << 32) ^ (cy & 0xffffffff); }
  const std::vector<int32_t>* cell(int64_t cx, int64_t cy) const;

  const LaneGraph& graph_;
  double cell_m_;
  std::unordered_map<int64_t, std::vector<int32_t>> cells_;
};

// Closest point of segment a→b to p: parameter t in [0, 1] and distance.
NearestEdge closest_on_segment(double ax, double ay, double bx, double by, double px, double py);

}  // namespace nsg::graph
