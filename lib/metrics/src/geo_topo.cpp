// GEO and TOPO precision/recall/F1 exactly as METRICS.md "Precise choices for GEO/TOPO"
// (rule numbers below refer to that section).
#include <algorithm>
#include <cmath>
#include <limits>
#include <functional>
#include <vector>

#include "internal.h"

namespace nsg::metrics::detail {
namespace {

constexpr double kCeilTol = 1e-9;      // rule 2: k = max(1, ceil(L/step - 1e-9))
constexpr double kQuantScale = 1e6;    // rule 4: q = floor(d2 * 1e6 + 0.5)
constexpr double kRadiusTolPx = 1e-6;  // rule 6: path radius inclusive tolerance

// One segment's run of samples (rule 3): end samples a (node i) and b (node j), interior
// samples first .. first + k - 2 from the a end, k pieces of length w.
struct Chain {
  int32_t a, b, first, k;
  double w;
  bool fwd, bwd;  // traversable a -> b, b -> a on the directed sample graph
};

// Samples of a graph (rule 2) and its sample graph (rule 3) stored as chains between node
// samples, so radius searches run Dijkstra over nodes only and walk the chains.
struct SampleGraph {
  std::vector<Point> pos;
  int32_t n_node_samples = 0;               // samples 0 .. n-1 are nodes
  std::vector<Chain> chains;                // by increasing (i, j)
  std::vector<int32_t> chain_offset;        // CSR: chains incident to each node sample
  std::vector<int32_t> chain_ids;
  std::vector<int32_t> chain_of_interior;   // interior sample - n_node_samples -> chain

  size_t size() const { return pos.size(); }
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
  sg.n_node_samples = static_cast<int32_t>(sg.pos.size());
  sg.chains.reserve(segs.size());
  sg.chain_offset.assign(sg.pos.size() + 1, 0);
  for (const Segment& s : segs) {
    const Point a = g.nodes[s.i], b = g.nodes[s.j];
    const double dx = b.u - a.u, dy = b.v - a.v;
    const double len = std::sqrt(dx * dx + dy * dy);
    const int k = std::max(1, static_cast<int>(std::ceil(len / step_px - kCeilTol)));
    const auto chain = static_cast<int32_t>(sg.chains.size());
    sg.chains.push_back({sample_of[s.i], sample_of[s.j], static_cast<int32_t>(sg.pos.size()), k,
                         len / k, s.fwd, s.bwd});
    ++sg.chain_offset[sample_of[s.i] + 1];
    ++sg.chain_offset[sample_of[s.j] + 1];
    for (int s_idx = 1; s_idx < k; ++s_idx) {
      const double t = static_cast<double>(s_idx) / k;
      sg.pos.push_back({a.u + dx * t, a.v + dy * t});
      sg.chain_of_interior.push_back(chain);
    }
  }
  for (int32_t n = 0; n < sg.n_node_samples; ++n) sg.chain_offset[n + 1] += sg.chain_offset[n];
  sg.chain_ids.resize(sg.chain_offset.back());
  std::vector<int32_t> fill(sg.chain_offset.begin(), sg.chain_offset.end() - 1);
  for (size_t c = 0; c < sg.chains.size(); ++c) {
    sg.chain_ids[fill[sg.chains[c].a]++] = static_cast<int32_t>(c);
    sg.chain_ids[fill[sg.chains[c].b]++] = static_cast<int32_t>(c);
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

// Samples within `radius` path length of `src` (src included), reusing buffers. Exactly
// the Dijkstra of rule 6 over the sample graph: a distance there is the minimum over paths
// of the pieces added one by one, and since adding a piece is monotone, Dijkstra over node
// samples whose chain "weight" adds the k pieces one by one gives the same node distances;
// an interior sample is within the radius iff it is from one of its chain's ends or the
// seed, walking piece by piece.
class RadiusSearch {
 public:
  explicit RadiusSearch(const SampleGraph& sg)
      : sg_(sg), dist_(static_cast<size_t>(sg.n_node_samples), kUnset), mark_(sg.size(), -1) {}

  const std::vector<int32_t>& run(int32_t src, bool directed, double radius) {
    for (int32_t n : touched_) dist_[n] = kUnset;
    touched_.clear();
    reached_.clear();
    heap_.clear();
    ++stamp_;
    directed_ = directed;
    radius_ = radius;
    const Chain* seed_chain = nullptr;
    int32_t s0 = 0;
    if (src < sg_.n_node_samples) {
      relax(src, 0.0);
    } else {
      seed_chain = &sg_.chains[sg_.chain_of_interior[src - sg_.n_node_samples]];
      s0 = src - seed_chain->first + 1;
      if (to_a(*seed_chain)) relax(seed_chain->a, walk(0.0, seed_chain->w, s0));
      if (to_b(*seed_chain)) relax(seed_chain->b, walk(0.0, seed_chain->w, seed_chain->k - s0));
    }
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), std::greater<>());
      const auto [d, n] = heap_.back();
      heap_.pop_back();
      if (d > dist_[n]) continue;
      for (int32_t k = sg_.chain_offset[n]; k < sg_.chain_offset[n + 1]; ++k) {
        const Chain& c = sg_.chains[sg_.chain_ids[k]];
        if (n == c.a ? to_b(c) : to_a(c)) relax(n == c.a ? c.b : c.a, walk(d, c.w, c.k));
      }
    }
    reached_.assign(touched_.begin(), touched_.end());
    for (int32_t n : touched_) {
      for (int32_t k = sg_.chain_offset[n]; k < sg_.chain_offset[n + 1]; ++k) {
        const Chain& c = sg_.chains[sg_.chain_ids[k]];
        if (n == c.a ? to_b(c) : to_a(c)) mark_interior(c, n == c.a, dist_[n], 0);
      }
    }
    if (seed_chain != nullptr) {
      mark(src);
      // From the seed towards b (positions s0+1 ..) and towards a (positions s0-1 ..).
      if (to_b(*seed_chain)) mark_interior(*seed_chain, true, 0.0, s0);
      if (to_a(*seed_chain)) mark_interior(*seed_chain, false, 0.0, seed_chain->k - s0);
    }
    return reached_;
  }

 private:
  static constexpr double kUnset = std::numeric_limits<double>::infinity();
  using Item = std::pair<double, int32_t>;

  bool to_b(const Chain& c) const { return !directed_ || c.fwd; }
  bool to_a(const Chain& c) const { return !directed_ || c.bwd; }

  // d plus `steps` pieces of length w, added one at a time as the sample-graph Dijkstra
  // does; kUnset once beyond the radius (its pruning, which is monotone).
  double walk(double d, double w, int32_t steps) const {
    for (int32_t s = 0; s < steps; ++s) {
      d += w;
      if (d > radius_) return kUnset;
    }
    return d;
  }
  void relax(int32_t n, double d) {
    if (!(d < dist_[n])) return;
    if (dist_[n] == kUnset) touched_.push_back(n);
    dist_[n] = d;
    heap_.push_back({d, n});
    std::push_heap(heap_.begin(), heap_.end(), std::greater<>());
  }
  void mark(int32_t sample) {
    if (mark_[sample] == stamp_) return;
    mark_[sample] = stamp_;
    reached_.push_back(sample);
  }
  // Interior samples of c reached walking from one end (from_a: the a end, positions
  // 1, 2, ..; else the b end, positions k-1, k-2, ..) starting at distance d, `skip`
  // positions beyond that end already passed (used for a seed inside the chain).
  void mark_interior(const Chain& c, bool from_a, double d, int32_t skip) {
    for (int32_t step = skip + 1; step < c.k; ++step) {
      d += c.w;
      if (d > radius_) return;
      mark(from_a ? c.first + step - 1 : c.first + (c.k - step) - 1);
    }
  }

  const SampleGraph& sg_;
  std::vector<double> dist_;  // node samples only
  std::vector<int32_t> mark_;
  int32_t stamp_ = 0;
  bool directed_ = false;
  double radius_ = 0.0;
  std::vector<Item> heap_;
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

// Rules 6-8 on the undirected or the directed sample graphs. The restricted
// matching visits its candidates in global (q, g, p) order through a bitmap of ranks,
// which avoids sorting per seed.
TopoSums topo_sums(const SampleGraph& gt, const SampleGraph& pred, bool directed,
                   const std::vector<Candidate>& cands, const CandidatesByG& by_g,
                   const std::vector<std::pair<int32_t, int32_t>>& seeds, double radius_px) {
  TopoSums sums;
  RadiusSearch search_g(gt), search_p(pred);
  // Stamps avoid clearing per-seed marks.
  std::vector<int32_t> in_p(pred.size(), -1), used_g(gt.size(), -1), used_p(pred.size(), -1);
  std::vector<uint64_t> bits((cands.size() + 63) / 64, 0);
  for (size_t s = 0; s < seeds.size(); ++s) {
    const auto stamp = static_cast<int32_t>(s);
    const std::vector<int32_t>& rp = search_p.run(seeds[s].second, directed, radius_px);
    for (int32_t p : rp) in_p[p] = stamp;
    const size_t n_rp = rp.size();
    const std::vector<int32_t>& rg = search_g.run(seeds[s].first, directed, radius_px);
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
  const TopoSums und = topo_sums(g, p, false, cands, by_g, seeds, radius_px);
  const TopoSums dir = topo_sums(g, p, true, cands, by_g, seeds, radius_px);
  r.topo_precision = ratio(und.precision_sum, np);
  r.topo_recall = ratio(und.recall_sum, ng);
  r.topo_f1 = f1_of(r.topo_precision, r.topo_recall);
  r.topo_directed_precision = ratio(dir.precision_sum, np);
  r.topo_directed_recall = ratio(dir.recall_sum, ng);
  r.topo_directed_f1 = f1_of(r.topo_directed_precision, r.topo_directed_recall);
  return r;
}

}  // namespace nsg::metrics::detail
