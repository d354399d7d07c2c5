// Lane segments and areas of a key frame (frame_map.h): the location's lanelines, crossings
// and drivable-area rings prepared once, then cut around each frame.
#include "nsg/frames/frame_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nsg::frames {
namespace {

// Points of a drivable-area ring per chunk: a frame clips only the chunks near its window,
// so a city-sized ring costs a frame a few chunks, not its thousands of points.
constexpr size_t kChunkSegments = 32;
// Area ids: crossings by map index, road boundaries above them by ring and piece.
constexpr int64_t kBoundaryIdBase = 1'000'000'000;
constexpr int64_t kIdsPerRing = 1000;

Eigen::Vector2d node_xy(const nuscenes::MapExpansion& map, nuscenes::MapIndex n) {
  const nuscenes::MapNode& node = map.nodes()[static_cast<size_t>(n)];
  return {node.x_m, node.y_m};
}

// A lane's divider segments as a boundary (nodes that did not resolve are left out).
LaneBoundary boundary_of(const nuscenes::MapExpansion& map, const std::vector<nuscenes::LaneDividerSegment>& segs) {
  LaneBoundary b;
  for (const nuscenes::LaneDividerSegment& s : segs) {
    if (s.node == nuscenes::kNoMapIndex) continue;
    const Eigen::Vector2d p = node_xy(map, s.node);
    if (!b.points.empty() && p == b.points.back()) continue;
    b.points.push_back(p);
    b.types.push_back(line_type_of(s.segment_type));
  }
  if (b.points.size() < 2) return {};
  b.types.pop_back();  // one type per stretch
  return b;
}

// Along the lane: a boundary whose far end is nearer the lane's start is turned round.
void orient(LaneBoundary& b, const Eigen::Vector2d& lane_start) {
  if (b.points.empty() || (b.points.front() - lane_start).norm() <= (b.points.back() - lane_start).norm()) return;
  std::reverse(b.points.begin(), b.points.end());
  std::reverse(b.types.begin(), b.types.end());
}

double width_between(const LaneBoundary& left, const LaneBoundary& right, bool at_end) {
  if (left.points.empty() || right.points.empty()) return std::numeric_limits<double>::quiet_NaN();
  return at_end ? (left.points.back() - right.points.back()).norm()
                : (left.points.front() - right.points.front()).norm();
}

BoundaryRing ring_of(const nuscenes::MapExpansion& map, const std::vector<nuscenes::MapIndex>& nodes) {
  std::vector<Eigen::Vector2d> points;
  for (const nuscenes::MapIndex n : nodes)
    if (n != nuscenes::kNoMapIndex) points.push_back(node_xy(map, n));
  return boundary_ring(std::move(points));
}

// The arc length along `line` of the point of it nearest to `p`.
double project_along(const std::vector<Eigen::Vector2d>& line, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity(), best_s = 0.0, s = 0.0;
  for (size_t k = 0; k + 1 < line.size(); ++k) {
    const Eigen::Vector2d d = line[k + 1] - line[k];
    const double len = d.norm();
    const double t = len > 0.0 ? std::clamp((p - line[k]).dot(d) / (len * len), 0.0, 1.0) : 0.0;
    const double dist = (line[k] + d * t - p).norm();
    if (dist < best) best = dist, best_s = s + t * len;
    s += len;
  }
  return best_s;
}

struct SubLine {
  std::vector<Eigen::Vector2d> points;
  LineType type = LineType::kNone;
};

// The stretch of `b` between arc lengths s0 < s1, with the type that covers most of it.
SubLine cut(const LaneBoundary& b, double s0, double s1) {
  SubLine out;
  double along[3] = {0, 0, 0};  // length per LineType
  double s = 0.0;
  for (size_t k = 0; k + 1 < b.points.size(); ++k) {
    const Eigen::Vector2d& a = b.points[k];
    const Eigen::Vector2d& c = b.points[k + 1];
    const double len = (c - a).norm();
    const double lo = std::max(s0, s), hi = std::min(s1, s + len);
    if (hi > lo && len > 0.0) {
      const Eigen::Vector2d from = a + (c - a) * ((lo - s) / len), to = a + (c - a) * ((hi - s) / len);
      if (out.points.empty() || from != out.points.back()) out.points.push_back(from);
      out.points.push_back(to);
      along[static_cast<int>(b.types[k])] += hi - lo;
    }
    s += len;
  }
  // Ties go to the stricter line: solid over dash over none.
  out.type = along[1] >= along[2] && along[1] >= along[0] && along[1] > 0.0 ? LineType::kSolid
             : along[2] >= along[0] && along[2] > 0.0                       ? LineType::kDash
                                                                            : LineType::kNone;
  return out;
}

// The line moved sideways by `offset_m` (left positive) on the map plane (global x, y: a
// move in the ego frame would leave the plane under a pitched or rolled pose), each point
// along the mean of its neighbouring segments' left normals.
std::vector<Eigen::Vector2d> offset_line(const std::vector<Eigen::Vector2d>& line, double offset_m) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(line.size());
  for (size_t k = 0; k < line.size(); ++k) {
    Eigen::Vector2d d = line[k + 1 == line.size() ? k : k + 1] - line[k == 0 ? 0 : k - 1];
    const double len = d.norm();
    if (len > 0.0) d /= len;
    out.push_back(line[k] + Eigen::Vector2d(-d.y(), d.x()) * offset_m);
  }
  return out;
}

// The ego-frame z of the map plane (global z = 0) above ego (x, y): what a map point
// clipped in x, y gets, as the centerlines' points do.
double map_plane_z(const geometry::Rigid3& global_from_ego, double x, double y) {
  const Eigen::Matrix3d& r = global_from_ego.rotation;
  const double z =
      std::abs(r(2, 2)) > 1e-9 ? -(r(2, 0) * x + r(2, 1) * y + global_from_ego.translation.z()) / r(2, 2) : 0.0;
  return z + 0.0;  // no "-0.0" in a record
}

std::vector<Eigen::Vector3d> to_ego(const std::vector<Eigen::Vector2d>& global,
                                    const geometry::Rigid3& ego_from_global) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(global.size());
  for (const Eigen::Vector2d& p : global) out.push_back(ego_from_global.apply(Eigen::Vector3d(p.x(), p.y(), 0.0)));
  return out;
}

// One side of a lane segment: the lane's divider cut to the piece, or the piece moved by
// the half width.
void laneline(const FrameCenterline& piece, const LaneBoundary& boundary, double offset_m,
              const geometry::Rigid3& global_from_ego, const geometry::Rigid3& ego_from_global, int points,
              std::vector<Eigen::Vector3d>* line, LineType* type, bool* from_offset) {
  if (!boundary.points.empty()) {
    const Eigen::Vector3d first = global_from_ego.apply(piece.points_2m.front());
    const Eigen::Vector3d last = global_from_ego.apply(piece.points_2m.back());
    double length = 0.0;
    for (size_t k = 0; k + 1 < boundary.points.size(); ++k)
      length += (boundary.points[k + 1] - boundary.points[k]).norm();
    const double s0 = piece.starts_at_lane_start ? 0.0 : project_along(boundary.points, first.head<2>());
    const double s1 = piece.ends_at_lane_end ? length : project_along(boundary.points, last.head<2>());
    const SubLine sub = cut(boundary, s0, s1);
    if (sub.points.size() >= 2) {
      *line = resample_by_count(to_ego(sub.points, ego_from_global), points);
      *type = sub.type;
      *from_offset = false;
      return;
    }
  }
  std::vector<Eigen::Vector2d> global;
  global.reserve(piece.points_2m.size());
  for (const Eigen::Vector3d& p : piece.points_2m) global.push_back(global_from_ego.apply(p).head<2>());
  *line = resample_by_count(to_ego(offset_line(global, offset_m), ego_from_global), points);
  *type = LineType::kNone;
  *from_offset = true;
}

// The polyline pieces of one drivable-area ring inside the window: the chunks near it
// (global bounding boxes), each run of consecutive chunks clipped as one chain, and the
// piece through the ring's closing point joined back into one.
void boundary_pieces(const BoundaryRing& ring, size_t ring_index, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                     const geometry::Rigid3& ego_from_global, const WindowM& window, std::vector<FrameArea>* out) {
  std::vector<std::vector<Eigen::Vector3d>> pieces;
  bool first_at_start = false, last_at_end = false;
  size_t k = 0;
  while (k < ring.chunks.size()) {
    const auto near = [&](const BoundaryRing::Chunk& c) {
      return c.max.x() >= lo.x() && c.min.x() <= hi.x() && c.max.y() >= lo.y() && c.min.y() <= hi.y();
    };
    if (!near(ring.chunks[k])) {
      ++k;
      continue;
    }
    size_t end = k;
    while (end + 1 < ring.chunks.size() && near(ring.chunks[end + 1])) ++end;
    const size_t from = ring.chunks[k].first, to = ring.chunks[end].last;
    std::vector<Eigen::Vector3d> chain;
    chain.reserve(to - from + 1);
    for (size_t p = from; p <= to; ++p)
      chain.push_back(ego_from_global.apply(Eigen::Vector3d(ring.points[p].x(), ring.points[p].y(), 0.0)));
    for (FrameCenterline& c : clip_chain(chain, window, -1, "", false)) {
      if (pieces.empty()) first_at_start = from == 0 && c.starts_at_lane_start;
      last_at_end = to + 1 == ring.points.size() && c.ends_at_lane_end;
      pieces.push_back(std::move(c.points_2m));
    }
    k = end + 1;
  }
  // The stretch through the ring's closing point came out as its last and first pieces:
  // joined into one line (a ring inside the window whole is one piece already).
  if (pieces.size() >= 2 && first_at_start && last_at_end) {
    pieces.back().insert(pieces.back().end(), pieces.front().begin() + 1, pieces.front().end());
    pieces.erase(pieces.begin());
  }
  for (size_t p = 0; p < pieces.size(); ++p)
    out->push_back({kBoundaryIdBase + static_cast<int64_t>(ring_index) * kIdsPerRing + static_cast<int64_t>(p),
                    AreaCategory::kRoadBoundary, std::move(pieces[p])});
}

}  // namespace

BoundaryRing boundary_ring(std::vector<Eigen::Vector2d> points) {
  BoundaryRing r;
  r.points = std::move(points);
  if (r.points.size() >= 2 && r.points.front() == r.points.back()) r.points.pop_back();
  if (r.points.size() < 3) return {};
  r.points.push_back(r.points.front());
  for (size_t first = 0; first + 1 < r.points.size(); first += kChunkSegments) {
    BoundaryRing::Chunk c;
    c.first = first;
    c.last = std::min(first + kChunkSegments, r.points.size() - 1);
    c.min = c.max = r.points[first];
    for (size_t k = first; k <= c.last; ++k) {
      c.min = c.min.cwiseMin(r.points[k]);
      c.max = c.max.cwiseMax(r.points[k]);
    }
    r.chunks.push_back(c);
  }
  return r;
}

LineType line_type_of(std::string_view segment_type) {
  if (segment_type.find("SOLID") != std::string_view::npos) return LineType::kSolid;
  if (segment_type.find("DASH") != std::string_view::npos) return LineType::kDash;
  return LineType::kNone;
}

LocationMapElements location_map_elements(const nuscenes::MapExpansion& map, const graph::LaneGraph& graph) {
  LocationMapElements out;
  const size_t n = graph.lanes.size();
  out.left.resize(n);
  out.right.resize(n);
  out.half_width_m.assign(n, kDefaultLaneWidthM / 2.0);
  std::vector<double> start_width(n, std::numeric_limits<double>::quiet_NaN()), end_width = start_width;
  for (size_t l = 0; l < n; ++l) {
    const graph::Lane& lane = graph.lanes[l];
    if (lane.is_connector || lane.nodes.empty()) continue;
    const std::optional<nuscenes::MapIndex> m = map.find(nuscenes::MapLayer::kLane, lane.token);
    if (!m) continue;
    const nuscenes::Lane& record = map.lanes()[static_cast<size_t>(*m)];
    const graph::Node& start = graph.nodes[static_cast<size_t>(lane.nodes.front())];
    out.left[l] = boundary_of(map, record.left_lane_divider_segments);
    out.right[l] = boundary_of(map, record.right_lane_divider_segments);
    orient(out.left[l], {start.x_m, start.y_m});
    orient(out.right[l], {start.x_m, start.y_m});
    start_width[l] = width_between(out.left[l], out.right[l], false);
    end_width[l] = width_between(out.left[l], out.right[l], true);
    const double mean = 0.5 * (start_width[l] + end_width[l]);
    if (std::isfinite(mean) && mean > 0.0) out.half_width_m[l] = mean / 2.0;
  }
  // A connector: the mean width of the lanes it joins, at the ends it joins them.
  std::vector<std::vector<int32_t>> predecessors(n);
  for (size_t l = 0; l < n; ++l)
    for (const int32_t s : graph.lanes[l].successors)
      predecessors[static_cast<size_t>(s)].push_back(static_cast<int32_t>(l));
  for (size_t l = 0; l < n; ++l) {
    if (!graph.lanes[l].is_connector) continue;
    double sum = 0.0;
    int count = 0;
    for (const int32_t p : predecessors[l])
      if (std::isfinite(end_width[static_cast<size_t>(p)])) sum += end_width[static_cast<size_t>(p)], ++count;
    for (const int32_t s : graph.lanes[l].successors)
      if (std::isfinite(start_width[static_cast<size_t>(s)])) sum += start_width[static_cast<size_t>(s)], ++count;
    if (count > 0 && sum > 0.0) out.half_width_m[l] = sum / count / 2.0;
  }
  for (const nuscenes::PedCrossing& c : map.ped_crossings()) {
    std::vector<Eigen::Vector2d> ring;
    if (c.polygon != nuscenes::kNoMapIndex)
      for (const nuscenes::MapIndex v : map.polygons()[static_cast<size_t>(c.polygon)].exterior_nodes)
        if (v != nuscenes::kNoMapIndex) ring.push_back(node_xy(map, v));
    out.ped_crossings.push_back(std::move(ring));  // kept when empty: ids stay the map's order
  }
  for (const nuscenes::DrivableArea& area : map.drivable_areas())
    for (const nuscenes::MapIndex p : area.polygons) {
      const nuscenes::MapPolygon& polygon = map.polygons()[static_cast<size_t>(p)];
      // The null-token polygon some real maps carry is the map-sized stand-in every null
      // link resolves to (the devkit's), not a road's outline: its ring is the canvas edge.
      if (polygon.token.empty()) continue;
      if (BoundaryRing r = ring_of(map, polygon.exterior_nodes); !r.points.empty())
        out.road_boundaries.push_back(std::move(r));
      for (const nuscenes::MapHole& hole : polygon.holes)
        if (BoundaryRing r = ring_of(map, hole.nodes); !r.points.empty()) out.road_boundaries.push_back(std::move(r));
    }
  return out;
}

std::vector<Eigen::Vector2d> clip_polygon_to_window(const std::vector<Eigen::Vector2d>& ring, const WindowM& w) {
  std::vector<Eigen::Vector2d> poly = ring, next;
  // Each edge of the window as (axis, bound, keep the side above it).
  const struct {
    int axis;
    double bound;
    bool above;
  } edges[4] = {{0, w.x_min_m, true}, {0, w.x_max_m, false}, {1, w.y_min_m, true}, {1, w.y_max_m, false}};
  for (const auto& e : edges) {
    next.clear();
    const auto inside = [&](const Eigen::Vector2d& p) { return e.above ? p[e.axis] >= e.bound : p[e.axis] <= e.bound; };
    for (size_t k = 0; k < poly.size(); ++k) {
      const Eigen::Vector2d& a = poly[k];
      const Eigen::Vector2d& b = poly[(k + 1) % poly.size()];
      const bool in_a = inside(a), in_b = inside(b);
      if (in_a) next.push_back(a);
      if (in_a != in_b) {
        const double t = (e.bound - a[e.axis]) / (b[e.axis] - a[e.axis]);
        Eigen::Vector2d c = a + (b - a) * t;
        c[e.axis] = e.bound;  // exactly on the edge
        next.push_back(c);
      }
    }
    poly.swap(next);
    if (poly.empty()) break;
  }
  return poly.size() >= 3 ? poly : std::vector<Eigen::Vector2d>{};
}

FrameMapElements cut_frame_map(const FrameLanes& lanes, const LocationMapElements& map,
                               const geometry::Rigid3& global_from_ego, const WindowM& window, int points) {
  const geometry::Rigid3 ego_from_global = global_from_ego.inverse();
  FrameMapElements out;
  out.lane_segments.reserve(lanes.centerlines.size());
  for (const FrameCenterline& c : lanes.centerlines) {
    const auto l = static_cast<size_t>(c.lane);
    FrameLaneSegment s;
    s.id = c.id;
    s.is_intersection_or_connector = c.is_connector;
    s.centerline = resample_by_count(c.points_2m, points);
    laneline(c, map.left[l], map.half_width_m[l], global_from_ego, ego_from_global, points, &s.left_laneline,
             &s.left_type, &s.left_from_offset);
    laneline(c, map.right[l], -map.half_width_m[l], global_from_ego, ego_from_global, points, &s.right_laneline,
             &s.right_type, &s.right_from_offset);
    out.lane_segments.push_back(std::move(s));
  }
  // The window's global bounding box: which crossings and ring chunks can reach it.
  Eigen::Vector2d lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Eigen::Vector2d& corner : window_corners_global(global_from_ego, window)) {
    lo = lo.cwiseMin(corner);
    hi = hi.cwiseMax(corner);
  }
  for (size_t k = 0; k < map.ped_crossings.size(); ++k) {
    const std::vector<Eigen::Vector2d>& ring = map.ped_crossings[k];
    if (ring.size() < 3) continue;
    Eigen::Vector2d rmin = ring.front(), rmax = ring.front();
    for (const Eigen::Vector2d& p : ring) rmin = rmin.cwiseMin(p), rmax = rmax.cwiseMax(p);
    if (rmax.x() < lo.x() || rmin.x() > hi.x() || rmax.y() < lo.y() || rmin.y() > hi.y()) continue;
    std::vector<Eigen::Vector2d> ego;
    for (const Eigen::Vector3d& p : to_ego(ring, ego_from_global)) ego.emplace_back(p.x(), p.y());
    const std::vector<Eigen::Vector2d> clipped = clip_polygon_to_window(ego, window);
    if (clipped.empty()) continue;
    FrameArea a{static_cast<int64_t>(k) * kIdsPerRing, AreaCategory::kPedestrianCrossing, {}};
    for (const Eigen::Vector2d& p : clipped)
      a.points.emplace_back(p.x(), p.y(), map_plane_z(global_from_ego, p.x(), p.y()));
    a.points.push_back(a.points.front());
    out.areas.push_back(std::move(a));
  }
  for (size_t r = 0; r < map.road_boundaries.size(); ++r)
    boundary_pieces(map.road_boundaries[r], r, lo, hi, ego_from_global, window, &out.areas);
  return out;
}

}  // namespace nsg::frames
