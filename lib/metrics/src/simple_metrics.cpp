// Direction accuracy, Dice/F1 + IoU masks and Chamfer distance (docs/metrics.md).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "internal.h"
#include "spatial.h"

namespace nsg::metrics::detail {
namespace {
// Tolerances that are part of the v1 definitions (docs/metrics.md "Parameters").
constexpr double kDirectionTiePx = 1e-9;
constexpr double kCapsulePx = 1e-9;
}  // namespace

SegmentDistance point_segment(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  const double len2 = dx * dx + dy * dy;
  double t = 0.0;
  if (len2 > 0.0) t = std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0);
  const double qx = ax + t * dx - px, qy = ay + t * dy - py;
  return {qx * qx + qy * qy, t};
}

std::optional<double> ratio(double num, double den) {
  if (den == 0.0) return std::nullopt;
  return num / den;
}

std::optional<double> f1_of(std::optional<double> p, std::optional<double> r) {
  if (!p && !r) return std::nullopt;
  if (!p || !r) return 0.0;
  if (*p + *r == 0.0) return 0.0;
  return 2.0 * *p * *r / (*p + *r);
}

DirectionResult compute_direction(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params) {
  struct Seg {
    double ax, ay, bx, by;
  };
  std::vector<Seg> gt_segs;  // directed, non-zero length
  std::vector<SegmentGrid::Box> boxes;
  for (const auto& [i, j] : gt.edges) {
    const Point a = gt.nodes[i], b = gt.nodes[j];
    if (a.u == b.u && a.v == b.v) continue;
    gt_segs.push_back({a.u, a.v, b.u, b.v});
    boxes.push_back({std::min(a.u, b.u), std::min(a.v, b.v), std::max(a.u, b.u), std::max(a.v, b.v)});
  }
  // Only GT segments within the match radius (plus margin) of a midpoint can decide it:
  // if the nearest is farther the edge is unmatched, and the ties at dmin + 1e-9 lie
  // within the radius too.
  const SegmentGrid grid(boxes, params.direction_match_px + 1e-6);
  DirectionResult r;
  double matched_len = 0.0, correct_len = 0.0;
  std::vector<double> dist(gt_segs.size());
  for (const auto& [i, j] : pred.edges) {
    const Point a = pred.nodes[i], b = pred.nodes[j];
    const double dx = b.u - a.u, dy = b.v - a.v;
    if (dx == 0.0 && dy == 0.0) continue;
    ++r.pred_edges;
    if (gt_segs.empty()) continue;
    const double mx = (a.u + b.u) / 2.0, my = (a.v + b.v) / 2.0;
    double dmin = std::numeric_limits<double>::infinity();
    const auto [first, last] = grid.near(mx, my);
    for (const int32_t* k = first; k != last; ++k) {
      const Seg& s = gt_segs[*k];
      dist[*k] = std::sqrt(point_segment(mx, my, s.ax, s.ay, s.bx, s.by).d2);
      dmin = std::min(dmin, dist[*k]);
    }
    if (!(dmin <= params.direction_match_px)) continue;
    const double len = std::sqrt(dx * dx + dy * dy);
    ++r.matched;
    matched_len += len;
    for (const int32_t* k = first; k != last; ++k) {
      if (dist[*k] > dmin + kDirectionTiePx) continue;
      const Seg& s = gt_segs[*k];
      if (dx * (s.bx - s.ax) + dy * (s.by - s.ay) > 0.0) {
        ++r.correct;
        correct_len += len;
        break;
      }
    }
  }
  if (r.matched > 0) {
    r.accuracy = static_cast<double>(r.correct) / static_cast<double>(r.matched);
    r.accuracy_length_weighted = correct_len / matched_len;
  }
  r.matched_fraction = ratio(static_cast<double>(r.matched), static_cast<double>(r.pred_edges));
  return r;
}

namespace {
// Lane mask: pixel centre within width/2 (+ tolerance) of a segment (exact capsule).
std::vector<uint8_t> render_mask(const CleanGraph& g, const MetricParams& params) {
  const int n = params.size_px;
  std::vector<uint8_t> mask(static_cast<size_t>(n) * n, 0);
  const double radius = params.lane_width_px / 2.0 + kCapsulePx;
  const double r2_in = radius * radius * (1.0 - 1e-12), r2_out = radius * radius * (1.0 + 1e-12);
  for (const Segment& s : segments_of(g)) {
    const Point a = g.nodes[s.i], b = g.nodes[s.j];
    const int u0 = std::max(0, static_cast<int>(std::floor(std::min(a.u, b.u) - radius)));
    const int u1 = std::min(n - 1, static_cast<int>(std::ceil(std::max(a.u, b.u) + radius)));
    const int v0 = std::max(0, static_cast<int>(std::floor(std::min(a.v, b.v) - radius)));
    const int v1 = std::min(n - 1, static_cast<int>(std::ceil(std::max(a.v, b.v) + radius)));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        uint8_t& px = mask[static_cast<size_t>(v) * n + u];
        if (px) continue;
        // sqrt only near the boundary: far inside or outside the squared test decides.
        const double d2 = point_segment(u, v, a.u, a.v, b.u, b.v).d2;
        if (d2 < r2_in || (d2 <= r2_out && std::sqrt(d2) <= radius)) px = 1;
      }
    }
  }
  return mask;
}
}  // namespace

MaskResult compute_masks(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params) {
  const std::vector<uint8_t> g = render_mask(gt, params), p = render_mask(pred, params);
  MaskResult r;
  for (size_t k = 0; k < g.size(); ++k) {
    r.gt_px += g[k];
    r.pred_px += p[k];
    r.inter_px += g[k] & p[k];
    r.union_px += g[k] | p[k];
  }
  return r;
}

ChamferResult compute_chamfer(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params) {
  ChamferResult r;
  if (gt.nodes.empty() && pred.nodes.empty()) {
    r.px2 = r.m2 = r.mean_m = 0.0;
    return r;
  }
  if (gt.nodes.empty() || pred.nodes.empty()) return r;
  // One direction: (sum of squared nearest distances, sum of nearest distances).
  // The nearest squared distance is the same double as an all-pairs scan's (the minimum of
  // the same values) and the sums run over xs in order, so the result is unchanged.
  auto one_way = [](const std::vector<Point>& xs, const std::vector<Point>& ys) {
    const PointGrid grid(ys);
    double sum2 = 0.0, sum1 = 0.0;
    for (const Point& x : xs) {
      const double best = grid.nearest_d2(x);
      sum2 += best;
      sum1 += std::sqrt(best);
    }
    return std::pair{sum2, sum1};
  };
  const auto [g2, g1] = one_way(gt.nodes, pred.nodes);
  const auto [p2, p1] = one_way(pred.nodes, gt.nodes);
  r.px2 = g2 + p2;
  r.m2 = *r.px2 * (params.resolution_m * params.resolution_m);
  r.mean_m = 0.5 * (g1 / static_cast<double>(gt.nodes.size()) + p1 / static_cast<double>(pred.nodes.size())) *
             params.resolution_m;
  return r;
}

}  // namespace nsg::metrics::detail
