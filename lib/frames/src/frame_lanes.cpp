// Cutting the lane graph around a key frame: node chains to the ego frame, clipped to the
// window, pieces and their successor links.
#include "nsg/frames/frame_lanes.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "nsg/graph/clip.h"

namespace nsg::frames {
namespace {

constexpr int64_t kIdsPerLane = 1000;  // a lane leaves and re-enters a 100 m window a few times at most

Eigen::Vector3d lerp(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t) { return a + (b - a) * t; }

// The stretches of one lane's chain (already in the ego frame) inside the box.
class PieceBuilder {
 public:
  PieceBuilder(const graph::TileBounds& box, int32_t lane, const std::string& token, bool is_connector)
      : box_(box), lane_(lane), token_(token), is_connector_(is_connector) {}

  std::vector<FrameCenterline> run(const std::vector<Eigen::Vector3d>& chain) {
    const size_t last = chain.size() - 1;
    for (size_t s = 0; s < last; ++s) {
      const Eigen::Vector3d& a = chain[s];
      const Eigen::Vector3d& b = chain[s + 1];
      double t0 = 0.0, t1 = 1.0;
      if (!graph::clip_segment(a.x(), a.y(), b.x(), b.y(), box_, &t0, &t1)) {
        close(false);
        continue;
      }
      // A stretch goes on across a node only when the segment before ended inside (t1 = 1)
      // and this one starts there (t0 = 0).
      if (!open_ || t0 > 0.0) {
        close(false);
        open_piece(lerp(a, b, t0), s == 0 && t0 == 0.0);
      }
      append(lerp(a, b, t1));
      if (t1 < 1.0) close(false);
    }
    close(true);
    return std::move(pieces_);
  }

 private:
  void open_piece(const Eigen::Vector3d& p, bool at_lane_start) {
    FrameCenterline c;
    c.lane = lane_;
    c.lane_token = token_;
    c.is_connector = is_connector_;
    c.starts_at_lane_start = at_lane_start;
    c.points_2m.push_back(p);
    current_ = std::move(c);
    open_ = true;
  }
  void append(const Eigen::Vector3d& p) {
    if (p != current_.points_2m.back()) current_.points_2m.push_back(p);
  }
  // `at_lane_end`: the chain ended with this stretch open, inside the window.
  void close(bool at_lane_end) {
    if (!open_) return;
    open_ = false;
    if (current_.points_2m.size() < 2) return;  // a touch of the border, no length
    current_.ends_at_lane_end = at_lane_end;
    current_.id = static_cast<int64_t>(lane_) * kIdsPerLane + static_cast<int64_t>(pieces_.size());
    pieces_.push_back(std::move(current_));
  }

  graph::TileBounds box_;
  int32_t lane_;
  const std::string& token_;
  bool is_connector_;
  bool open_ = false;
  FrameCenterline current_;
  std::vector<FrameCenterline> pieces_;
};

}  // namespace

std::vector<FrameCenterline> clip_chain(const std::vector<Eigen::Vector3d>& chain, const WindowM& window, int32_t lane,
                                        const std::string& token, bool is_connector) {
  if (chain.size() < 2) return {};
  const graph::TileBounds box{window.x_min_m, window.y_min_m, window.x_max_m, window.y_max_m};
  return PieceBuilder(box, lane, token, is_connector).run(chain);
}

std::vector<Eigen::Vector3d> resample_by_count(const std::vector<Eigen::Vector3d>& polyline, int n) {
  std::vector<double> along(polyline.size(), 0.0);
  for (size_t i = 1; i < polyline.size(); ++i) along[i] = along[i - 1] + (polyline[i] - polyline[i - 1]).norm();
  const double length = along.back();
  std::vector<Eigen::Vector3d> out;
  out.reserve(static_cast<size_t>(n));
  size_t seg = 0;
  for (int k = 0; k < n; ++k) {
    if (k == n - 1) {
      out.push_back(polyline.back());
      break;
    }
    const double target = length * k / (n - 1);
    while (seg + 2 < polyline.size() && along[seg + 1] < target) ++seg;
    const double span = along[seg + 1] - along[seg];
    const double t = span > 0.0 ? std::clamp((target - along[seg]) / span, 0.0, 1.0) : 0.0;
    out.push_back(lerp(polyline[seg], polyline[seg + 1], t));
  }
  return out;
}

std::vector<Eigen::Vector2d> window_corners_global(const geometry::Rigid3& global_from_ego, const WindowM& w) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& [x, y] : {std::pair{w.x_min_m, w.y_min_m}, std::pair{w.x_max_m, w.y_min_m},
                             std::pair{w.x_max_m, w.y_max_m}, std::pair{w.x_min_m, w.y_max_m}}) {
    const Eigen::Vector3d g = global_from_ego.apply(Eigen::Vector3d(x, y, 0.0));
    out.emplace_back(g.x(), g.y());
  }
  return out;
}

FrameLanes cut_frame_lanes(const graph::LaneGraph& graph, const graph::SegmentIndex& index,
                           const geometry::Rigid3& global_from_ego, const WindowM& window, int centerline_points) {
  // The lanes with an edge near the window: the global bounding box of its corners.
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const Eigen::Vector2d& c : window_corners_global(global_from_ego, window)) {
    x0 = std::min(x0, c.x()), y0 = std::min(y0, c.y()), x1 = std::max(x1, c.x()), y1 = std::max(y1, c.y());
  }
  std::vector<int32_t> lanes;
  for (const int32_t e : index.query_box(x0, y0, x1, y1)) lanes.push_back(graph.edges[static_cast<size_t>(e)].lane);
  std::sort(lanes.begin(), lanes.end());
  lanes.erase(std::unique(lanes.begin(), lanes.end()), lanes.end());

  const geometry::Rigid3 ego_from_global = global_from_ego.inverse();
  FrameLanes out;
  std::vector<Eigen::Vector3d> chain;
  for (const int32_t lane : lanes) {
    const graph::Lane& source = graph.lanes[static_cast<size_t>(lane)];
    if (source.nodes.size() < 2) continue;
    chain.clear();
    for (const int32_t n : source.nodes) {
      const graph::Node& node = graph.nodes[static_cast<size_t>(n)];
      chain.push_back(ego_from_global.apply(Eigen::Vector3d(node.x_m, node.y_m, 0.0)));
    }
    for (FrameCenterline& c : clip_chain(chain, window, lane, source.token, source.is_connector)) {
      c.points = resample_by_count(c.points_2m, centerline_points);
      out.centerlines.push_back(std::move(c));
    }
  }
  // Links: a piece that reaches its lane's end → a piece that starts at a successor's start.
  for (size_t a = 0; a < out.centerlines.size(); ++a) {
    const FrameCenterline& from = out.centerlines[a];
    if (!from.ends_at_lane_end) continue;
    const std::vector<int32_t>& next = graph.lanes[static_cast<size_t>(from.lane)].successors;
    for (size_t b = 0; b < out.centerlines.size(); ++b) {
      const FrameCenterline& to = out.centerlines[b];
      if (to.starts_at_lane_start && std::find(next.begin(), next.end(), to.lane) != next.end())
        out.successors.emplace_back(static_cast<int32_t>(a), static_cast<int32_t>(b));
    }
  }
  return out;
}

}  // namespace nsg::frames
