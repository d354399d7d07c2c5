#include "nsg/model/targets.h"

#include <cmath>
#include <limits>

#include "nsg/graph/segment_index.h"
#include "nsg/model/direction.h"

namespace nsg::model {

TileTargets compute_targets(const metrics::Graph& truth, int size_px, double max_distance_px) {
  // The tile graph in pixel units as a lane graph (x = u, y = v) for the segment index.
  graph::LaneGraph g;
  for (const auto& n : truth.nodes) g.nodes.push_back({n.u, n.v});
  for (const auto& e : truth.edges) {
    if (e[0] == e[1]) continue;
    g.edges.push_back({static_cast<int32_t>(e[0]), static_cast<int32_t>(e[1]), -1});
  }
  const graph::SegmentIndex index(g, 16.0);
  TileTargets t;
  t.distance_px.create(size_px, size_px, CV_32F);
  t.angle_rad.create(size_px, size_px, CV_32F);
  for (int v = 0; v < size_px; ++v) {
    for (int u = 0; u < size_px; ++u) {
      const graph::NearestEdge near = index.nearest(u, v, max_distance_px);
      if (near.edge < 0) {
        t.distance_px.at<float>(v, u) = static_cast<float>(max_distance_px);
        t.angle_rad.at<float>(v, u) = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const graph::Edge& e = g.edges[static_cast<size_t>(near.edge)];
      const graph::Node& a = g.nodes[static_cast<size_t>(e.source)];
      const graph::Node& b = g.nodes[static_cast<size_t>(e.target)];
      t.distance_px.at<float>(v, u) = static_cast<float>(near.distance_m);
      t.angle_rad.at<float>(v, u) = static_cast<float>(map_angle(b.x_m - a.x_m, b.y_m - a.y_m));
    }
  }
  return t;
}

}  // namespace nsg::model
