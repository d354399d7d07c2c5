// Direction accuracy, Dice/F1 + IoU masks and Chamfer distance (METRICS.md).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "internal.h"

namespace nsg::metrics::detail {
namespace {
// Tolerances that are part of the v1 definitions (METRICS.md "Details").
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

namespace {

// Segments bucketed on a uniform grid by their bounding boxes grown by `reach`: every
// segment within `reach` of a point is listed in that point's cell (and possibly others).
class SegmentGrid {
 public:
  struct Box {
    double u0, v0, u1, v1;
  };
  SegmentGrid(const std::vector<Box>& boxes, double reach) {
    if (boxes.empty()) return;
    u0_ = v0_ = std::numeric_limits<double>::infinity();
    double u1 = -u0_, v1 = -v0_;
    for (const Box& b : boxes) {
      u0_ = std::min(u0_, b.u0 - reach);
      v0_ = std::min(v0_, b.v0 - reach);
      u1 = std::max(u1, b.u1 + reach);
      v1 = std::max(v1, b.v1 + reach);
    }
    // At most ~kMaxCells per side whatever the coordinates (they are not clipped).
    cell_ = std::max({reach, (u1 - u0_) / kMaxCells, (v1 - v0_) / kMaxCells, 1e-9});
    nu_ = cell_of(u1, u0_) + 1;
    nv_ = cell_of(v1, v0_) + 1;
    offset_.assign(static_cast<size_t>(nu_ * nv_) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<int32_t> fill(offset_.begin(), offset_.end() - 1);
      if (pass == 1) ids_.resize(offset_.back());
      for (size_t k = 0; k < boxes.size(); ++k) {
        const Box& b = boxes[k];
        for (int64_t v = cell_of(b.v0 - reach, v0_); v <= cell_of(b.v1 + reach, v0_); ++v)
          for (int64_t u = cell_of(b.u0 - reach, u0_); u <= cell_of(b.u1 + reach, u0_); ++u) {
            const auto c = static_cast<size_t>(v * nu_ + u);
            if (pass == 0) ++offset_[c + 1];
            else ids_[fill[c]++] = static_cast<int32_t>(k);
          }
      }
      if (pass == 0)
        for (size_t c = 0; c + 1 < offset_.size(); ++c) offset_[c + 1] += offset_[c];
    }
  }
  // Segment indices listed in the cell of (u, v), increasing; empty outside the grid.
  std::pair<const int32_t*, const int32_t*> near(double u, double v) const {
    if (offset_.empty() || !(u >= u0_ && v >= v0_)) return {nullptr, nullptr};
    const int64_t cu = cell_of(u, u0_), cv = cell_of(v, v0_);
    if (cu >= nu_ || cv >= nv_) return {nullptr, nullptr};
    const auto c = static_cast<size_t>(cv * nu_ + cu);
    return {ids_.data() + offset_[c], ids_.data() + offset_[c + 1]};
  }

 private:
  static constexpr double kMaxCells = 256;
  int64_t cell_of(double x, double origin) const {
    return std::clamp<int64_t>(static_cast<int64_t>(std::floor((x - origin) / cell_)), 0, 4 * 1024);
  }
  double u0_ = 0, v0_ = 0, cell_ = 1;
  int64_t nu_ = 0, nv_ = 0;
  std::vector<int32_t> offset_, ids_;
};

}  // namespace

DirectionResult compute_direction(const CleanGraph& gt, const CleanGraph& pred,
                                  const MetricParams& params) {
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

ChamferResult compute_chamfer(const CleanGraph& gt, const CleanGraph& pred,
                              const MetricParams& params) {
  ChamferResult r;
  if (gt.nodes.empty() && pred.nodes.empty()) {
    r.px2 = r.m2 = r.mean_m = 0.0;
    return r;
  }
  if (gt.nodes.empty() || pred.nodes.empty()) return r;
  // One direction: (sum of squared nearest distances, sum of nearest distances).
  auto one_way = [](const std::vector<Point>& xs, const std::vector<Point>& ys) {
    double sum2 = 0.0, sum1 = 0.0;
    for (const Point& x : xs) {
      double best = std::numeric_limits<double>::infinity();
      for (const Point& y : ys) {
        const double dx = x.u - y.u, dy = x.v - y.v;
        best = std::min(best, dx * dx + dy * dy);
      }
      sum2 += best;
      sum1 += std::sqrt(best);
    }
    return std::pair{sum2, sum1};
  };
  const auto [g2, g1] = one_way(gt.nodes, pred.nodes);
  const auto [p2, p1] = one_way(pred.nodes, gt.nodes);
  r.px2 = g2 + p2;
  r.m2 = *r.px2 * (params.resolution_m * params.resolution_m);
  r.mean_m = 0.5 * (g1 / static_cast<double>(gt.nodes.size()) +
                    p1 / static_cast<double>(pred.nodes.size())) *
             params.resolution_m;
  return r;
}

}  // namespace nsg::metrics::detail
