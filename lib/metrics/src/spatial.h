#pragma once
// Uniform grids that replace all-pairs scans in the metrics. Both only prune: the
// distances themselves are computed by the callers exactly as before, so results
// (including ties broken by index) are bit-identical to the all-pairs scans.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "nsg/metrics/graph.h"

namespace nsg::metrics::detail {

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

// Exact nearest-neighbour squared distance to a point set: a uniform grid of about one
// point per cell searched in growing square rings until no unvisited cell can be closer.
// The minimum of the same d2 values as an all-pairs scan, hence the identical double.
class PointGrid {
 public:
  explicit PointGrid(const std::vector<Point>& pts) : pts_(pts) {
    if (pts.empty()) return;
    double u1 = -std::numeric_limits<double>::infinity(), v1 = u1;
    u0_ = v0_ = -u1;
    for (const Point& p : pts) {
      u0_ = std::min(u0_, p.u);
      v0_ = std::min(v0_, p.v);
      u1 = std::max(u1, p.u);
      v1 = std::max(v1, p.v);
    }
    const double extent = std::max({u1 - u0_, v1 - v0_, 1e-9});
    const auto side = static_cast<int64_t>(std::clamp(std::sqrt(static_cast<double>(pts.size())), 1.0, 256.0));
    cell_ = extent / static_cast<double>(side) * (1.0 + 1e-9);
    nu_ = std::max<int64_t>(1, cell_of(u1, u0_, kBig) + 1);
    nv_ = std::max<int64_t>(1, cell_of(v1, v0_, kBig) + 1);
    offset_.assign(static_cast<size_t>(nu_ * nv_) + 1, 0);
    for (const Point& p : pts) ++offset_[index(p) + 1];
    for (size_t c = 0; c + 1 < offset_.size(); ++c) offset_[c + 1] += offset_[c];
    ids_.resize(pts.size());
    std::vector<int32_t> fill(offset_.begin(), offset_.end() - 1);
    for (size_t k = 0; k < pts.size(); ++k) ids_[fill[index(pts[k])]++] = static_cast<int32_t>(k);
  }

  // min over the points of dx*dx + dy*dy (infinity if there are none).
  double nearest_d2(Point q) const {
    double best = std::numeric_limits<double>::infinity();
    if (pts_.empty()) return best;
    const int64_t cu = std::clamp<int64_t>(cell_of(q.u, u0_, nu_), 0, nu_ - 1);
    const int64_t cv = std::clamp<int64_t>(cell_of(q.v, v0_, nv_), 0, nv_ - 1);
    for (int64_t r = 0;; ++r) {
      const int64_t ulo = cu - r, uhi = cu + r, vlo = cv - r, vhi = cv + r;
      for (int64_t v = std::max<int64_t>(vlo, 0); v <= std::min(vhi, nv_ - 1); ++v) {
        const bool edge_row = v == vlo || v == vhi;
        for (int64_t u = std::max<int64_t>(ulo, 0); u <= std::min(uhi, nu_ - 1); ++u) {
          if (!edge_row && u != ulo && u != uhi) continue;  // only the ring
          const auto c = static_cast<size_t>(v * nu_ + u);
          for (int32_t k = offset_[c]; k < offset_[c + 1]; ++k) {
            const Point& p = pts_[ids_[k]];
            const double dx = q.u - p.u, dy = q.v - p.v;
            best = std::min(best, dx * dx + dy * dy);
          }
        }
      }
      if (ulo <= 0 && vlo <= 0 && uhi >= nu_ - 1 && vhi >= nv_ - 1) return best;
      // Every unvisited point lies outside the visited box of cells; stop once that box's
      // distance from q (less a margin for rounding) exceeds the best distance so far.
      const double gap =
          std::min({q.u - (u0_ + static_cast<double>(ulo) * cell_), u0_ + static_cast<double>(uhi + 1) * cell_ - q.u,
                    q.v - (v0_ + static_cast<double>(vlo) * cell_), v0_ + static_cast<double>(vhi + 1) * cell_ - q.v}) -
          kMargin * (cell_ + std::abs(q.u) + std::abs(q.v));
      if (gap > 0.0 && gap * gap > best) return best;
    }
  }

 private:
  static constexpr int64_t kBig = int64_t{1} << 20;
  static constexpr double kMargin = 1e-9;
  int64_t cell_of(double x, double origin, int64_t n) const {
    const double c = std::floor((x - origin) / cell_);
    if (!(c >= 0.0)) return c < 0.0 ? -1 : 0;  // NaN-free inputs; left of the grid
    return c >= static_cast<double>(n) ? n : static_cast<int64_t>(c);
  }
  size_t index(const Point& p) const {
    const int64_t u = std::clamp<int64_t>(cell_of(p.u, u0_, nu_), 0, nu_ - 1);
    const int64_t v = std::clamp<int64_t>(cell_of(p.v, v0_, nv_), 0, nv_ - 1);
    return static_cast<size_t>(v * nu_ + u);
  }
  const std::vector<Point>& pts_;
  double u0_ = 0, v0_ = 0, cell_ = 1;
  int64_t nu_ = 1, nv_ = 1;
  std::vector<int32_t> offset_, ids_;
};

}  // namespace nsg::metrics::detail
