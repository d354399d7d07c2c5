#include "nsg/graph/segment_index.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nsg::graph {

NearestEdge closest_on_segment(double ax, double ay, double bx, double by, double px, double py) {
  const double dx = bx - ax, dy = by - ay;
  const double len2 = dx * dx + dy * dy;
  double t = 0.0;
  if (len2 > 0.0) t = std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0);
  NearestEdge r;
  r.t = t;
  r.x_m = ax + t * dx;
  r.y_m = ay + t * dy;
  r.distance_m = std::hypot(px - r.x_m, py - r.y_m);
  return r;
}

SegmentIndex::SegmentIndex(const LaneGraph& graph, double cell_m) : graph_(graph), cell_m_(cell_m) {
  for (size_t e = 0; e < graph.edges.size(); ++e) {
    const Node& a = graph.nodes[graph.edges[e].source];
    const Node& b = graph.nodes[graph.edges[e].target];
    const int64_t cx0 = static_cast<int64_t>(std::floor(std::min(a.x_m, b.x_m) / cell_m_));
    const int64_t cx1 = static_cast<int64_t>(std::floor(std::max(a.x_m, b.x_m) / cell_m_));
    const int64_t cy0 = static_cast<int64_t>(std::floor(std::min(a.y_m, b.y_m) / cell_m_));
    const int64_t cy1 = static_cast<int64_t>(std::floor(std::max(a.y_m, b.y_m) / cell_m_));
    for (int64_t cy = cy0; cy <= cy1; ++cy)
      for (int64_t cx = cx0; cx <= cx1; ++cx) cells_[key(cx, cy)].push_back(static_cast<int32_t>(e));
  }
}

const std::vector<int32_t>* SegmentIndex::cell(int64_t cx, int64_t cy) const {
  auto it = cells_.find(key(cx, cy));
  return it == cells_.end() ? nullptr : &it->second;
}

std::vector<int32_t> SegmentIndex::query_box(double x_min, double y_min, double x_max, double y_max) const {
  std::vector<int32_t> out;
  const int64_t cx0 = static_cast<int64_t>(std::floor(x_min / cell_m_));
  const int64_t cx1 = static_cast<int64_t>(std::floor(x_max / cell_m_));
  const int64_t cy0 = static_cast<int64_t>(std::floor(y_min / cell_m_));
  const int64_t cy1 = static_cast<int64_t>(std::floor(y_max / cell_m_));
  for (int64_t cy = cy0; cy <= cy1; ++cy) {
    for (int64_t cx = cx0; cx <= cx1; ++cx) {
      const std::vector<int32_t>* edges = cell(cx, cy);
      if (!edges) continue;
      for (int32_t e : *edges) {
        const Node& a = graph_.nodes[graph_.edges[e].source];
        const Node& b = graph_.nodes[graph_.edges[e].target];
        if (std::max(a.x_m, b.x_m) < x_min || std::min(a.x_m, b.x_m) > x_max || std::max(a.y_m, b.y_m) < y_min ||
            std::min(a.y_m, b.y_m) > y_max)
          continue;
        out.push_back(e);
      }
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

NearestEdge SegmentIndex::nearest(double x_m, double y_m, double max_distance_m) const {
  NearestEdge best;
  best.distance_m = std::numeric_limits<double>::infinity();
  const int64_t cx = static_cast<int64_t>(std::floor(x_m / cell_m_));
  const int64_t cy = static_cast<int64_t>(std::floor(y_m / cell_m_));
  const int64_t max_ring = static_cast<int64_t>(std::ceil(max_distance_m / cell_m_)) + 1;
  for (int64_t ring = 0; ring <= max_ring; ++ring) {
    // Anything in ring r is at least (r − 1) cells away; stop once that exceeds the best.
    if (ring >= 1 && static_cast<double>(ring - 1) * cell_m_ > best.distance_m) break;
    for (int64_t dy = -ring; dy <= ring; ++dy) {
      for (int64_t dx = -ring; dx <= ring; ++dx) {
        if (std::max(std::abs(dx), std::abs(dy)) != ring) continue;
        const std::vector<int32_t>* edges = cell(cx + dx, cy + dy);
        if (!edges) continue;
        for (int32_t e : *edges) {
          const Node& a = graph_.nodes[graph_.edges[e].source];
          const Node& b = graph_.nodes[graph_.edges[e].target];
          NearestEdge c = closest_on_segment(a.x_m, a.y_m, b.x_m, b.y_m, x_m, y_m);
          if (c.distance_m < best.distance_m || (c.distance_m == best.distance_m && e < best.edge)) {
            c.edge = e;
            best = c;
          }
        }
      }
    }
  }
  if (best.edge < 0 || best.distance_m > max_distance_m) return NearestEdge{};
  return best;
}

}  // namespace nsg::graph
