// GEO and TOPO precision/recall/F1 exactly as METRICS.md "Precise choices for GEO/TOPO"
// (rule numbers below refer to that section).
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <vector>

#include "internal.h"

namespace nsg::metrics::detail {
namespace {

constexpr double kCeilTol = 1e-9;      // rule 2: k = max(1, ceil(L/step - 1e-9))
constexpr double kQuantScale = 1e6;    // rule 4: q = floor(d2 * 1e6 + 0.5)
constexpr double kRadiusTolPx = 1e-6;  // rule 6: path radius inclusive tolerance

struct Arc {
  int32_t to;
  double w;
};

// Samples of a graph (rule 2) and its undirected and directed sample graphs (rule 3).
struct SampleGraph {
  std::vector<Point> pos;
  std::vector<std::vector<Arc>> undirected, directed;

  size_t size() const { return pos.size(); }
  void add_piece(int32_t a, int32_t b, double w, bool fwd, bool bwd) {
    undirected[a].push_back({b, w});
    undirected[b].push_back({a, w});
    if (fwd) directed[a].push_back({b, w});
    if (bwd) directed[b].push_back({a, w});
  }
};

SampleGraph sample_graph(const CleanGraph& g, double step_px) {
  const std::vector<Segment> segs = segments_of(g);
  std::vector<int32_t> sample_of(g.nodes.size(), -1);
  for (const Segment& s : segs) sample_of[s.i] = sample_of[s.j] = 0;
  SampleGraph sg;
  for (size_t n = 0; n < g.nodes.size(); ++n) {
    if (sample_of[n] < 0) continue;
    sample_of[n] = static_cast<int32_t>(sg.pos.size());
    sg.pos.push_back(g.nodes[n]);
  }
  struct Pending {
    int32_t first_interior;
    int k;
    double w;
  };
  std::vector<Pending> pending;
  pending.reserve(segs.size());
  for (const Segment& s : segs) {
    const Point a = g.nodes[s.i], b = g.nodes[s.j];
    const double dx = b.u - a.u, dy = b.v - a.v;
    const double len = std::sqrt(dx * dx + dy * dy);
    const int k = std::max(1, static_cast<int>(std::ceil(len / step_px - kCeilTol)));
    pending.push_back({static_cast<int32_t>(sg.pos.size()), k, len / k});
    for (int s_idx = 1; s_idx < k; ++s_idx) {
      const double t = static_cast<double>(s_idx) / k;
      sg.pos.push_back({a.u + dx * t, a.v + dy * t});
    }
  }
  sg.undirected.resize(sg.pos.size());
  sg.directed.resize(sg.pos.size());
  for (size_t k = 0; k < segs.size(); ++k) {
    const Segment& s = segs[k];
    const Pending& p = pending[k];
    int32_t prev = sample_of[s.i];
    for (int s_idx = 1; s_idx < p.k; ++s_idx) {
      const int32_t cur = p.first_interior + s_idx - 1;
      sg.add_piece(prev, cur, p.w, s.fwd, s.bwd);
      prev = cur;
    }
    sg.add_piece(prev, sample_of[s.j], p.w, s.fwd, s.bwd);
  }
  return sg;
}

struct Candidate {
  int64_t q;
  int32_t g, p;
};

// All pairs within the match radius, sorted by (q, g, p) (rule 4). Pred samples are
// bucketed on a grid of the match radius so only neighbouring cells are tested.
std::vector<Candidate> candidates(const SampleGraph& gt, const SampleGraph& pred, double match_px) {
  std::vector<Candidate> out;
  if (gt.size() == 0 || pred.size() == 0) return out;
  const auto q_max = static_cast<int64_t>(std::floor(match_px * match_px * kQuantScale + 0.5));
  double u0 = std::numeric_limits<double>::infinity(), v0 = u0;
  for (const Point& p : pred.pos) {
    u0 = std::min(u0, p.u);
    v0 = std::min(v0, p.v);
  }
  const double cell = std::max(match_px, 1e-3);
  auto cell_of = [&](double x, double origin) {
    return static_cast<int64_t>(std::floor((x - origin) / cell));
  };
  int64_t nu = 1, nv = 1;
  for (const Point& p : pred.pos) {
    nu = std::max(nu, cell_of(p.u, u0) + 1);
    nv = std::max(nv, cell_of(p.v, v0) + 1);
  }
  std::vector<std::vector<int32_t>> grid(static_cast<size_t>(nu * nv));
  for (size_t k = 0; k < pred.size(); ++k)
    grid[cell_of(pred.pos[k].v, v0) * nu + cell_of(pred.pos[k].u, u0)].push_back(static_cast<int32_t>(k));
  for (size_t gi = 0; gi < gt.size(); ++gi) {
    const Point g = gt.pos[gi];
    const int64_t cu = cell_of(g.u, u0), cv = cell_of(g.v, v0);
    for (int64_t v = std::max<int64_t>(0, cv - 1); v <= std::min(nv - 1, cv + 1); ++v) {
      for (int64_t u = std::max<int64_t>(0, cu - 1); u <= std::min(nu - 1, cu + 1); ++u) {
        for (int32_t pi : grid[v * nu + u]) {
          const double dx = g.u - pred.pos[pi].u, dy = g.v - pred.pos[pi].v;
          const double d2 = dx * dx + dy * dy;
          const auto q = static_cast<int64_t>(std::floor(d2 * kQuantScale + 0.5));
          if (q <= q_max) out.push_back({q, static_cast<int32_t>(gi), pi});
        }
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    if (a.q != b.q) return a.q < b.q;
    if (a.g != b.g) return a.g < b.g;
    return a.p < b.p;
  });
  return out;
}

// Samples within `radius` path length of `src` (src included), reusing buffers.
class RadiusSearch {
 public:
  explicit RadiusSearch(size_t n) : dist_(n, kUnset) {}
  const std::vector<int32_t>& run(const std::vector<std::vector<Arc>>& adj, int32_t src, double radius) {
    for (int32_t n : reached_) dist_[n] = kUnset;
    reached_.clear();
    using Item = std::pair<double, int32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    dist_[src] = 0.0;
    touched_.assign(1, src);
    heap.push({0.0, src});
    while (!heap.empty()) {
      const auto [d, n] = heap.top();
      heap.pop();
      if (d > dist_[n]) continue;
      reached_.push_back(n);
      for (const Arc& a : adj[n]) {
        const double nd = d + a.w;
        if (nd > radius) continue;
        if (dist_[a.to] == kUnset) touched_.push_back(a.to);
        if (nd < dist_[a.to]) {
          dist_[a.to] = nd;
          heap.push({nd, a.to});
        }
      }
    }
    for (int32_t n : touched_) dist_[n] = kUnset;
    touched_.clear();
    return reached_;
  }

 private:
  static constexpr double kUnset = std::numeric_limits<double>::infinity();
  std::vector<double> dist_;
  std::vector<int32_t> reached_, touched_;
};

struct TopoSums {
  double precision_sum = 0.0, recall_sum = 0.0;
};

// Candidates grouped by GT sample (CSR), each with its global rank and pred sample.
struct CandidatesByG {
  std::vector<int32_t> offset;                    // size N_G + 1
  std::vector<std::pair<int32_t, int32_t>> rank_p;  // (rank in the sorted list, p)
};

// Rules 6-8 for one pair of adjacency lists (undirected or directed). The restricted
// matching visits its candidates in global (q, g, p) order through a bitmap of ranks,
// which avoids sorting per seed.
TopoSums topo_sums(const SampleGraph& gt, const SampleGraph& pred,
                   const std::vector<std::vector<Arc>>& gt_adj,
                   const std::vector<std::vector<Arc>>& pred_adj,
                   const std::vector<Candidate>& cands, const CandidatesByG& by_g,
                   const std::vector<std::pair<int32_t, int32_t>>& seeds, double radius_px) {
  TopoSums sums;
  RadiusSearch search_g(gt.size()), search_p(pred.size());
  // Stamps avoid clearing per-seed marks.
  std::vector<int32_t> in_p(pred.size(), -1), used_g(gt.size(), -1), used_p(pred.size(), -1);
  std::vector<uint64_t> bits((cands.size() + 63) / 64, 0);
  for (size_t s = 0; s < seeds.size(); ++s) {
    const auto stamp = static_cast<int32_t>(s);
    const std::vector<int32_t>& rp = search_p.run(pred_adj, seeds[s].second, radius_px);
    for (int32_t p : rp) in_p[p] = stamp;
    const size_t n_rp = rp.size();
    const std::vector<int32_t>& rg = search_g.run(gt_adj, seeds[s].first, radius_px);
    size_t lo = bits.size(), hi = 0;  // range of words of `bits` set for this seed
    for (int32_t g : rg) {
      for (int32_t k = by_g.offset[g]; k < by_g.offset[g + 1]; ++k) {
        const auto [rank, p] = by_g.rank_p[k];
        if (in_p[p] != stamp) continue;
        const size_t wi = static_cast<size_t>(rank) >> 6;
        lo = std::min(lo, wi);
        hi = std::max(hi, wi + 1);
        bits[wi] |= uint64_t{1} << (rank & 63);
      }
    }
    int64_t m = 0;
    for (size_t wi = lo; wi < hi; ++wi) {
      uint64_t w = bits[wi];
      bits[wi] = 0;
      while (w != 0) {
        const int bit = __builtin_ctzll(w);
        w &= w - 1;
        const Candidate& c = cands[(static_cast<size_t>(wi) << 6) + bit];
        if (used_g[c.g] == stamp || used_p[c.p] == stamp) continue;
        used_g[c.g] = used_p[c.p] = stamp;
        ++m;
      }
    }
    sums.precision_sum += static_cast<double>(m) / static_cast<double>(n_rp);
    sums.recall_sum += static_cast<double>(m) / static_cast<double>(rg.size());
  }
  return sums;
}

}  // namespace

GeoTopoResult compute_geo_topo(const CleanGraph& gt, const CleanGraph& pred,
                               const MetricParams& params) {
  const SampleGraph g = sample_graph(gt, params.geo_step_px);
  const SampleGraph p = sample_graph(pred, params.geo_step_px);
  GeoTopoResult r;
  r.gt_samples = static_cast<int64_t>(g.size());
  r.pred_samples = static_cast<int64_t>(p.size());

  // Rule 4/5: greedy one-to-one GEO matching.
  const std::vector<Candidate> cands = candidates(g, p, params.geo_match_px);
  std::vector<int32_t> match_of_g(g.size(), -1);
  std::vector<uint8_t> p_used(p.size(), 0);
  CandidatesByG by_g;
  by_g.offset.assign(g.size() + 1, 0);
  for (const Candidate& c : cands) ++by_g.offset[c.g + 1];
  for (size_t k = 0; k < g.size(); ++k) by_g.offset[k + 1] += by_g.offset[k];
  by_g.rank_p.resize(cands.size());
  {
    std::vector<int32_t> fill(by_g.offset.begin(), by_g.offset.end() - 1);
    for (size_t k = 0; k < cands.size(); ++k)
      by_g.rank_p[fill[cands[k].g]++] = {static_cast<int32_t>(k), cands[k].p};
  }
  for (size_t k = 0; k < cands.size(); ++k) {
    const Candidate& c = cands[k];
    if (match_of_g[c.g] >= 0 || p_used[c.p]) continue;
    match_of_g[c.g] = c.p;
    p_used[c.p] = 1;
    ++r.matched;
  }
  const auto ng = static_cast<double>(r.gt_samples), np = static_cast<double>(r.pred_samples);
  const auto m = static_cast<double>(r.matched);
  r.geo_precision = ratio(m, np);
  r.geo_recall = ratio(m, ng);
  r.geo_f1 = ratio(2.0 * m, ng + np);

  // Rules 6-8: seeds in increasing g.
  std::vector<std::pair<int32_t, int32_t>> seeds;
  for (size_t k = 0; k < g.size(); ++k)
    if (match_of_g[k] >= 0) seeds.push_back({static_cast<int32_t>(k), match_of_g[k]});
  r.seeds = static_cast<int64_t>(seeds.size());
  const double radius_px = params.topo_radius_m / params.resolution_m + kRadiusTolPx;
  const TopoSums und = topo_sums(g, p, g.undirected, p.undirected, cands, by_g, seeds, radius_px);
  const TopoSums dir = topo_sums(g, p, g.directed, p.directed, cands, by_g, seeds, radius_px);
  r.topo_precision = ratio(und.precision_sum, np);
  r.topo_recall = ratio(und.recall_sum, ng);
  r.topo_f1 = f1_of(r.topo_precision, r.topo_recall);
  r.topo_directed_precision = ratio(dir.precision_sum, np);
  r.topo_directed_recall = ratio(dir.recall_sum, ng);
  r.topo_directed_f1 = f1_of(r.topo_directed_precision, r.topo_directed_recall);
  return r;
}

}  // namespace nsg::metrics::detail
