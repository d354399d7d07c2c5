#include "nsg/graph/projection.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <tuple>

#include "nsg/core/error.h"

namespace nsg::graph {

void ProjectionOptions::validate() const {
  if (!(max_distance_m > 0.0)) throw ConfigError("", "projection.max_distance_m", "expected > 0 m");
  if (!(max_follow_m >= 0.0)) throw ConfigError("", "projection.max_follow_m", "expected ≥ 0 m");
}

bool AdaptiveGroundTruth::has_connection(int32_t a, int32_t b) const {
  return std::find(connections.begin(), connections.end(), std::make_pair(a, b)) != connections.end();
}

namespace {

// Arc length from the lane's start to the source node of each of its edges.
std::vector<double> edge_offsets(const LaneGraph& graph) {
  std::vector<double> offset(graph.edges.size(), 0.0);
  int32_t lane = -1;
  double along = 0.0;
  for (size_t e = 0; e < graph.edges.size(); ++e) {
    if (graph.edges[e].lane != lane) {
      lane = graph.edges[e].lane;
      along = 0.0;
    }
    offset[e] = along;
    along += graph.edge_length_m(graph.edges[e]);
  }
  return offset;
}

// First projected point reachable from `lane`'s successors within `budget_m` of lane
// length, breadth first (lanes without points are passed through).
void connect_across(const LaneGraph& graph, int32_t from_point, int32_t lane,
                    const std::vector<int32_t>& first_point_of_lane, double budget_m, AdaptiveGroundTruth* gt) {
  std::deque<std::pair<int32_t, double>> queue;  // lane, length used before it
  std::vector<bool> seen(graph.lanes.size(), false);
  for (int32_t next : graph.lanes[lane].successors) queue.emplace_back(next, 0.0);
  while (!queue.empty()) {
    auto [l, used] = queue.front();
    queue.pop_front();
    if (seen[l]) continue;
    seen[l] = true;
    if (first_point_of_lane[l] >= 0) {
      gt->connections.emplace_back(from_point, first_point_of_lane[l]);
      continue;
    }
    const double through = used + graph.lanes[l].length_m;
    if (through > budget_m) continue;
    for (int32_t next : graph.lanes[l].successors) queue.emplace_back(next, through);
  }
}

// The projected point nearest each node among those on an edge that starts or ends there
// (−1: none), ties to the lower point index.
std::vector<int32_t> nearest_point_at_node(const LaneGraph& graph, const std::vector<ProjectedPoint>& points) {
  std::vector<int32_t> best(graph.nodes.size(), -1);
  std::vector<double> best_m(graph.nodes.size(), 0.0);
  for (size_t k = 0; k < points.size(); ++k) {
    const Edge& e = graph.edges[static_cast<size_t>(points[k].edge)];
    for (const int32_t n : {e.source, e.target}) {
      const Node& node = graph.nodes[static_cast<size_t>(n)];
      const double d = std::hypot(points[k].x_m - node.x_m, points[k].y_m - node.y_m);
      if (best[n] < 0 || d < best_m[n]) {
        best[n] = static_cast<int32_t>(k);
        best_m[n] = d;
      }
    }
  }
  return best;
}

void link_lane_changes(const LaneGraph& graph, AdaptiveGroundTruth* gt) {
  if (graph.lane_changes.empty()) return;
  const std::vector<int32_t> at = nearest_point_at_node(graph, gt->points);
  for (const LaneChange& c : graph.lane_changes) {
    const int32_t a = at[static_cast<size_t>(c.source)], b = at[static_cast<size_t>(c.target)];
    if (a >= 0 && b >= 0 && a != b) gt->lane_changes.emplace_back(a, b);
  }
  std::sort(gt->lane_changes.begin(), gt->lane_changes.end());
  gt->lane_changes.erase(std::unique(gt->lane_changes.begin(), gt->lane_changes.end()), gt->lane_changes.end());
}

}  // namespace

AdaptiveGroundTruth project_onto_lanes(const LaneGraph& graph, const SegmentIndex& index,
                                       const std::vector<Node>& points, const ProjectionOptions& options) {
  options.validate();
  const std::vector<double> offset = edge_offsets(graph);
  AdaptiveGroundTruth gt;
  for (size_t i = 0; i < points.size(); ++i) {
    const NearestEdge hit = index.nearest(points[i].x_m, points[i].y_m, options.max_distance_m);
    if (hit.edge < 0) continue;
    const Edge& edge = graph.edges[hit.edge];
    ProjectedPoint p;
    p.input = static_cast<int32_t>(i);
    p.lane = edge.lane;
    p.edge = hit.edge;
    p.x_m = hit.x_m;
    p.y_m = hit.y_m;
    p.along_lane_m = offset[hit.edge] + hit.t * graph.edge_length_m(edge);
    p.distance_m = hit.distance_m;
    gt.points.push_back(p);
  }
  std::sort(gt.points.begin(), gt.points.end(), [](const ProjectedPoint& a, const ProjectedPoint& b) {
    return std::tie(a.lane, a.along_lane_m, a.input) < std::tie(b.lane, b.along_lane_m, b.input);
  });

  std::vector<int32_t> first(graph.lanes.size(), -1), last(graph.lanes.size(), -1);
  for (size_t k = 0; k < gt.points.size(); ++k) {
    const int32_t lane = gt.points[k].lane;
    if (first[lane] < 0) first[lane] = static_cast<int32_t>(k);
    if (last[lane] >= 0) gt.connections.emplace_back(last[lane], static_cast<int32_t>(k));
    last[lane] = static_cast<int32_t>(k);
  }
  for (size_t lane = 0; lane < graph.lanes.size(); ++lane) {
    if (last[lane] >= 0)
      connect_across(graph, last[lane], static_cast<int32_t>(lane), first, options.max_follow_m, &gt);
  }
  link_lane_changes(graph, &gt);
  return gt;
}

}  // namespace nsg::graph
