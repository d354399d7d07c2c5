// The change metrics of a map-update tile (docs/metrics.md "Map change"): where the current
// map differs from the prior one by more than the GEO match radius, and whether the
// prediction follows the current map there and the prior map elsewhere. Every test is
// "is some sample of the other set within geo_match_px" with GEO rule 4's integer key, so a
// copy of either map scores its extremes exactly.
#include <cmath>
#include <limits>
#include <vector>

#include "geo_topo_samples.h"
#include "internal.h"

namespace nsg::metrics::detail {
namespace {

constexpr double kQuantScale = 1e6;  // GEO rule 4: q = floor(d2 * 1e6 + 0.5)

// The points of `b` bucketed on a grid of the match radius, asked per point of `a` whether
// any lies within the radius (rule 4's key, inclusive). Each pair tested costs one unit.
class Coverage {
 public:
  Coverage(const std::vector<Point>& b, double match_px, WorkMeter& meter)
      : b_(b),
        q_max_(static_cast<int64_t>(std::floor(match_px * match_px * kQuantScale + 0.5))),
        cell_(std::max(match_px, 1e-3)),
        meter_(meter) {
    if (b_.empty()) return;
    u0_ = v0_ = std::numeric_limits<double>::infinity();
    for (const Point& p : b_) {
      u0_ = std::min(u0_, p.u);
      v0_ = std::min(v0_, p.v);
    }
    for (const Point& p : b_) {
      nu_ = std::max(nu_, cell_of(p.u, u0_) + 1);
      nv_ = std::max(nv_, cell_of(p.v, v0_) + 1);
    }
    grid_.resize(static_cast<size_t>(nu_ * nv_));
    for (size_t k = 0; k < b_.size(); ++k)
      grid_[static_cast<size_t>(cell_of(b_[k].v, v0_) * nu_ + cell_of(b_[k].u, u0_))].push_back(
          static_cast<int32_t>(k));
  }

  bool near(const Point& a) const {
    if (b_.empty()) return false;
    const int64_t cu = cell_of(a.u, u0_), cv = cell_of(a.v, v0_);
    for (int64_t v = std::max<int64_t>(0, cv - 1); v <= std::min(nv_ - 1, cv + 1); ++v) {
      for (int64_t u = std::max<int64_t>(0, cu - 1); u <= std::min(nu_ - 1, cu + 1); ++u) {
        for (const int32_t k : grid_[static_cast<size_t>(v * nu_ + u)]) {
          meter_.spend(1);
          const double dx = a.u - b_[k].u, dy = a.v - b_[k].v;
          if (static_cast<int64_t>(std::floor((dx * dx + dy * dy) * kQuantScale + 0.5)) <= q_max_) return true;
        }
      }
    }
    return false;
  }

  // near() for every point of `a`.
  std::vector<char> of(const std::vector<Point>& a) const {
    std::vector<char> out(a.size(), 0);
    for (size_t k = 0; k < a.size(); ++k) out[k] = near(a[k]) ? 1 : 0;
    return out;
  }

 private:
  int64_t cell_of(double x, double origin) const { return static_cast<int64_t>(std::floor((x - origin) / cell_)); }

  const std::vector<Point>& b_;
  int64_t q_max_;
  double cell_;
  WorkMeter& meter_;
  double u0_ = 0.0, v0_ = 0.0;
  int64_t nu_ = 1, nv_ = 1;
  std::vector<std::vector<int32_t>> grid_;
};

// `flags` bit of sample k (none when the graph carries no labels).
bool has_flag(const SampleGraph& sg, size_t k, uint8_t bit) { return !sg.flags.empty() && (sg.flags[k] & bit) != 0; }

// Change samples of one kind and how many were detected: recall = detected / samples.
void add_kind(ChangeResult::Kind& kind, bool detected) {
  ++kind.samples;
  kind.detected += detected ? 1 : 0;
}

}  // namespace

ChangeResult compute_changes(const CleanGraph& current, const CleanGraph& prior, const CleanGraph& pred,
                             const MetricParams& params, WorkMeter& meter) {
  const SampleGraph c = sample_graph(current, params.geo_step_px);
  const SampleGraph q = sample_graph(prior, params.geo_step_px);
  const SampleGraph x = sample_graph(pred, params.geo_step_px);
  const double r = params.geo_match_px;
  const Coverage to_c(c.pos, r, meter), to_q(q.pos, r, meter), to_x(x.pos, r, meter);
  const std::vector<char> c_near_q = to_q.of(c.pos), c_near_x = to_x.of(c.pos);
  const std::vector<char> q_near_c = to_c.of(q.pos), q_near_x = to_x.of(q.pos);
  const std::vector<char> x_near_c = to_c.of(x.pos), x_near_q = to_q.of(x.pos);

  ChangeResult out;
  // Change samples: the current map where the prior has nothing within the radius (an added
  // or moved lane's new place), detected when the prediction has a sample there; the prior
  // map where the current has nothing (a removed or moved lane's old place), detected when
  // the prediction has none there.
  std::vector<Point> changes;
  for (size_t k = 0; k < c.size(); ++k) {
    if (c_near_q[k] != 0) continue;
    changes.push_back(c.pos[k]);
    const bool detected = c_near_x[k] != 0;
    add_kind(out.all, detected);
    if (has_flag(c, k, kEdgeAdded)) add_kind(out.added, detected);
    if (has_flag(c, k, kEdgeMoved)) add_kind(out.moved, detected);
  }
  for (size_t k = 0; k < q.size(); ++k) {
    if (q_near_c[k] != 0) {
      // A prior sample the current map keeps: a change the prediction claims there is false.
      ++out.prior_kept;
      out.false_changes += q_near_x[k] == 0 ? 1 : 0;
      continue;
    }
    changes.push_back(q.pos[k]);
    const bool detected = q_near_x[k] == 0;
    add_kind(out.all, detected);
    if (has_flag(q, k, kEdgeRemoved)) add_kind(out.removed, detected);
    if (has_flag(q, k, kEdgeMoved)) add_kind(out.moved, detected);
  }
  // Claims: the prediction where the prior has nothing (claimed added), true when the current
  // map is there; the prior where the prediction has nothing (claimed removed), true when the
  // current map is not there either.
  for (size_t k = 0; k < x.size(); ++k) {
    if (x_near_q[k] != 0) continue;
    ++out.claims;
    out.true_claims += x_near_c[k] != 0 ? 1 : 0;
  }
  for (size_t k = 0; k < q.size(); ++k) {
    if (q_near_x[k] != 0) continue;
    ++out.claims;
    out.true_claims += q_near_c[k] == 0 ? 1 : 0;
  }
  // Away from every change sample, precision and recall against the current map.
  const Coverage to_change(changes, r, meter);
  for (size_t k = 0; k < x.size(); ++k) {
    if (to_change.near(x.pos[k])) continue;
    ++out.unchanged_pred;
    out.unchanged_pred_on_map += x_near_c[k] != 0 ? 1 : 0;
  }
  for (size_t k = 0; k < c.size(); ++k) {
    if (to_change.near(c.pos[k])) continue;
    ++out.unchanged_gt;
    out.unchanged_gt_found += c_near_x[k] != 0 ? 1 : 0;
  }
  return out;
}

}  // namespace nsg::metrics::detail
