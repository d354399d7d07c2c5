// GEO and TOPO precision/recall/F1 exactly as docs/metrics.md "GEO and TOPO" (rule
// numbers below refer to that section).
// The samples and GEO candidates are made in geo_topo_samples.cpp; this file holds the
// matching and the radius searches (rules 4-8).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <functional>
#include <vector>

#include "geo_topo_samples.h"
#include "internal.h"

namespace nsg::metrics::detail {
namespace {

constexpr double kRadiusTolPx = 1e-6;  // rule 6: path radius inclusive tolerance

// Samples within `radius` path length of `src` (src included), reusing buffers. Exactly
// the Dijkstra of rule 6 over the sample graph: a distance there is the minimum over paths
// of the pieces added one by one, and since adding a piece is monotone, Dijkstra over node
// samples whose chain "weight" adds the k pieces one by one gives the same node distances;
// an interior sample is within the radius iff it is from one of its chain's ends or the
// seed, walking piece by piece.
//
// The reach set is kept per chain as intervals of interior positions (1 .. k-1): a prefix
// reached from the a end, a suffix reached from the b end and, on the seed's chain, the
// run around the seed. Consecutive seeds reach nearly the same set, so diff() compares
// the intervals with those of the previous run and reports only the samples that changed,
// instead of walking every reached sample twice per seed.
class RadiusSearch {
 public:
  RadiusSearch(const SampleGraph& sg, WorkMeter& meter)
      : sg_(sg),
        meter_(meter),
        dist_(static_cast<size_t>(sg.n_node_samples), kUnset),
        prev_node_in_(static_cast<size_t>(sg.n_node_samples), 0),
        reach_(sg.chains.size()),
        prev_reach_(sg.chains.size()),
        listed_(sg.chains.size(), 0),
        through_(sg.chains.size(), 0) {}

  void run(int32_t src, bool directed, double radius) {
    start_generation();
    directed_ = directed;
    radius_ = radius;
    max_dist_ = 0.0;
    const Chain* seed_chain = nullptr;
    int32_t s0 = 0;
    if (src < sg_.n_node_samples) {
      relax(src, 0.0);
    } else {
      seed_chain_ = sg_.chain_of_interior[src - sg_.n_node_samples];
      seed_chain = &sg_.chains[seed_chain_];
      s0 = seed_s0_ = src - seed_chain->first + 1;
      if (to_a(*seed_chain)) relax(seed_chain->a, walk(0.0, seed_chain->w, s0));
      if (to_b(*seed_chain)) relax(seed_chain->b, walk(0.0, seed_chain->w, seed_chain->k - s0));
    }
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), std::greater<>());
      const auto [d, n] = heap_.back();
      heap_.pop_back();
      if (d > dist_[n]) continue;
      // n is final here: one walk along each chain gives both the interior samples it
      // reaches and the relaxation of the far end (the same partial sums).
      max_dist_ = std::max(max_dist_, d);
      meter_.spend(1 + sg_.chain_offset[n + 1] - sg_.chain_offset[n]);
      for (int32_t k = sg_.chain_offset[n]; k < sg_.chain_offset[n + 1]; ++k) {
        const int32_t ci = sg_.chain_ids[k];
        const Chain& c = sg_.chains[ci];
        if (!(n == c.a ? to_b(c) : to_a(c))) continue;
        // Walked end to end from its other end, settled earlier: every interior sample is
        // reached already and that end is final, so walking back changes neither the
        // reach set nor any node distance. (dist_to() may then give a longer path's
        // length for some interior samples: still the upper bound WholeComponent needs.)
        if (through_[ci]) continue;
        double dw = d, last_interior = d;
        int32_t steps = 0;
        while (steps < c.k) {
          const double next = dw + c.w;
          if (next > radius_) break;
          if (steps + 1 < c.k) last_interior = next;
          dw = next;
          ++steps;
        }
        meter_.spend(steps);
        if (steps == c.k) relax(n == c.a ? c.b : c.a, dw);
        const int32_t interior = std::min(steps, c.k - 1);
        if (interior == 0) continue;
        through_[ci] = steps == c.k ? 1 : 0;
        max_dist_ = std::max(max_dist_, last_interior);
        Reach& r = touch(ci);
        (n == c.a ? r.pre : r.suf) = interior;
      }
    }
    if (seed_chain != nullptr) {
      // From the seed towards b (positions s0+1 ..) and towards a (positions s0-1 ..).
      Reach& r = touch(seed_chain_);
      r.lo = r.hi = s0;
      if (to_b(*seed_chain)) r.hi += steps_within(seed_chain->w, seed_chain->k, 0.0, s0);
      if (to_a(*seed_chain)) r.lo -= steps_within(seed_chain->w, seed_chain->k, 0.0, seed_chain->k - s0);
    }
    count_ = static_cast<int64_t>(nodes_.size());
    for (int32_t c : chains_) count_ += reach_[c].count(sg_.chains[c].k);
  }

  // Reports every sample whose membership changed since the previous run as
  // set_in(sample, now_reached).
  template <class SetIn>
  void diff(SetIn set_in) const {
    for (int32_t n : prev_nodes_)
      if (dist_[n] == kUnset) set_in(n, false);
    for (int32_t n : nodes_)
      if (!prev_node_in_[n]) set_in(n, true);
    // prev_chains_ and chains_ may overlap: a chain in both is handled from prev_chains_.
    for (int32_t c : prev_chains_) diff_chain(c, set_in);
    for (int32_t c : chains_)
      if (prev_reach_[c].empty()) diff_chain(c, set_in);
  }

  // Of the last run(): the number of reached samples, an upper bound of the (computed)
  // path lengths to reached samples, and the computed length of a path to a reached
  // sample (the shortest one's, except on chains walked from one end only, see run()).
  int64_t count() const { return count_; }
  double max_dist() const { return max_dist_; }
  double dist_to(int32_t sample) const {
    if (sample < sg_.n_node_samples) return dist_[sample];
    const int32_t ci = sg_.chain_of_interior[sample - sg_.n_node_samples];
    const Chain& c = sg_.chains[ci];
    const Reach& r = reach_[ci];
    const int32_t s = sample - c.first + 1;
    double d = kUnset;
    if (s <= r.pre) d = std::min(d, add_steps(dist_[c.a], c.w, s));
    if (s >= c.k - r.suf) d = std::min(d, add_steps(dist_[c.b], c.w, c.k - s));
    if (r.lo <= s && s <= r.hi) d = std::min(d, add_steps(0.0, c.w, s > seed_s0_ ? s - seed_s0_ : seed_s0_ - s));
    return d;
  }

 private:
  static constexpr double kUnset = std::numeric_limits<double>::infinity();
  using Item = std::pair<double, int32_t>;

  // Interior positions of one chain reached: 1 .. pre, k - suf .. k - 1, lo .. hi.
  struct Reach {
    int32_t pre = 0, suf = 0, lo = 1, hi = 0;
    bool empty() const { return pre == 0 && suf == 0 && lo > hi; }
    bool has(int32_t s, int32_t k) const { return s <= pre || s >= k - suf || (lo <= s && s <= hi); }
    bool operator==(const Reach&) const = default;
    int64_t count(int32_t k) const {
      if (lo > hi) return std::min(k - 1, pre + suf);
      int64_t n = 0;
      for (int32_t s = 1; s < k; ++s) n += has(s, k) ? 1 : 0;
      return n;
    }
  };

  bool to_b(const Chain& c) const { return !directed_ || c.fwd; }
  bool to_a(const Chain& c) const { return !directed_ || c.bwd; }

  static double add_steps(double d, double w, int32_t steps) {
    for (int32_t s = 0; s < steps; ++s) d += w;
    return d;
  }
  // d plus `steps` pieces of length w, added one at a time as the sample-graph Dijkstra
  // does; kUnset once beyond the radius (its pruning, which is monotone).
  double walk(double d, double w, int32_t steps) const {
    for (int32_t s = 0; s < steps; ++s) {
      d += w;
      if (d > radius_) return kUnset;
    }
    return d;
  }
  // How many interior positions a walk from one end (or from the seed, `skip` positions
  // in) reaches starting at distance d; raises max_dist_ to the last one's distance.
  int32_t steps_within(double w, int32_t k, double d, int32_t skip) {
    int32_t n = 0;
    for (int32_t step = skip + 1; step < k; ++step) {
      d += w;
      if (d > radius_) break;
      max_dist_ = std::max(max_dist_, d);
      ++n;
    }
    return n;
  }
  void relax(int32_t n, double d) {
    if (!(d < dist_[n])) return;
    if (dist_[n] == kUnset) nodes_.push_back(n);
    dist_[n] = d;
    heap_.push_back({d, n});
    std::push_heap(heap_.begin(), heap_.end(), std::greater<>());
  }
  Reach& touch(int32_t c) {
    if (!listed_[c]) {
      listed_[c] = 1;
      chains_.push_back(c);
    }
    return reach_[c];
  }
  // The current run becomes the previous one.
  void start_generation() {
    for (int32_t n : prev_nodes_) prev_node_in_[n] = 0;
    for (int32_t n : nodes_) {
      prev_node_in_[n] = 1;
      dist_[n] = kUnset;
    }
    prev_nodes_.swap(nodes_);
    nodes_.clear();
    for (int32_t c : prev_chains_) prev_reach_[c] = Reach{};
    for (int32_t c : chains_) {
      prev_reach_[c] = reach_[c];
      reach_[c] = Reach{};
      listed_[c] = 0;
      through_[c] = 0;
    }
    prev_chains_.swap(chains_);
    chains_.clear();
    heap_.clear();
    seed_chain_ = -1;
  }
  template <class SetIn>
  void diff_chain(int32_t ci, SetIn& set_in) const {
    const Reach &now = reach_[ci], &before = prev_reach_[ci];
    if (now == before) return;
    const Chain& c = sg_.chains[ci];
    for (int32_t s = 1; s < c.k; ++s) {
      const bool in = now.has(s, c.k);
      if (in != before.has(s, c.k)) set_in(c.first + s - 1, in);
    }
  }

  const SampleGraph& sg_;
  WorkMeter& meter_;
  std::vector<double> dist_;  // node samples only
  std::vector<uint8_t> prev_node_in_;
  std::vector<Reach> reach_, prev_reach_;  // per chain; empty unless listed
  std::vector<uint8_t> listed_;            // chain is in chains_
  std::vector<uint8_t> through_;           // listed chain walked end to end (k >= 2)
  std::vector<int32_t> nodes_, prev_nodes_, chains_, prev_chains_;
  int32_t seed_chain_ = -1, seed_s0_ = 0;  // the seed's chain and position on it (interior seeds)
  bool directed_ = false;
  double radius_ = 0.0;
  std::vector<Item> heap_;
  double max_dist_ = 0.0;
  int64_t count_ = 0;
};

// Candidate ranks (indices into the sorted list) grouped by sample, each group ascending,
// with the candidate's sample on the other side (p or g) next to its rank.
struct RanksBy {
  struct Entry {
    int32_t rank, other;
  };
  std::vector<int32_t> offset;  // size N + 1
  std::vector<Entry> entries;
};

RanksBy ranks_by(size_t n, const std::vector<Candidate>& cands, bool by_g) {
  RanksBy r;
  r.offset.assign(n + 1, 0);
  for (const Candidate& c : cands) ++r.offset[(by_g ? c.g : c.p) + 1];
  for (size_t k = 0; k < n; ++k) r.offset[k + 1] += r.offset[k];
  r.entries.resize(cands.size());
  std::vector<int32_t> fill(r.offset.begin(), r.offset.end() - 1);
  for (size_t k = 0; k < cands.size(); ++k) {
    const int32_t at = fill[by_g ? cands[k].g : cands[k].p]++;
    r.entries[at] = {static_cast<int32_t>(k), by_g ? cands[k].p : cands[k].g};
  }
  return r;
}

// The greedy matching of rule 4 restricted to candidates whose g and p are both "in",
// kept up to date while the in-sets change from seed to seed. Consecutive seeds have
// nearly the same reach sets, so only the candidates whose presence changed, and those
// whose status a flip affects, are re-decided. A candidate is accepted iff it is present
// and no accepted candidate of lower rank shares its g or p; re-deciding candidates in
// increasing rank (a flip only affects higher ranks) reproduces exactly the one-pass
// greedy scan over the restricted list.
class IncrementalMatching {
 public:
  IncrementalMatching(const std::vector<Candidate>& cands, const RanksBy& by_g, const RanksBy& by_p, WorkMeter& meter)
      : meter_(meter),
        by_g_(by_g),
        by_p_(by_p),
        pair_(cands.size()),
        accepted_(cands.size(), 0),
        g_(by_g.offset.size() - 1),
        p_(by_p.offset.size() - 1),
        pending_((cands.size() + 63) / 64, 0),
        summary_((pending_.size() + 63) / 64, 0),
        lo_(summary_.size()) {
    for (size_t k = 0; k < cands.size(); ++k) pair_[k] = {cands[k].g, cands[k].p};
  }

  void set_g(int32_t g, bool in) { set(g_, p_, by_g_, g, in); }
  void set_p(int32_t p, bool in) { set(p_, g_, by_p_, p, in); }

  // Settles the pending re-decisions; returns the size of the restricted matching.
  int64_t matched() {
    // Pending ranks are a two-level bitmap scanned upwards: a decision only queues higher
    // ranks, so a word is final once its bits are cleared.
    if (hi_ > lo_) meter_.spend(static_cast<int64_t>(hi_ - lo_));
    for (size_t si = lo_; si < hi_; ++si) {
      while (summary_[si] != 0) {
        const size_t wi = (si << 6) + static_cast<size_t>(__builtin_ctzll(summary_[si]));
        while (pending_[wi] != 0) {
          const int bit = __builtin_ctzll(pending_[wi]);
          pending_[wi] &= pending_[wi] - 1;
          decide(static_cast<int32_t>((wi << 6) + static_cast<size_t>(bit)));
        }
        summary_[si] &= ~(uint64_t{1} << (wi & 63));
      }
    }
    lo_ = summary_.size();
    hi_ = 0;
    return m_;
  }

 private:
  static constexpr int32_t kNone = std::numeric_limits<int32_t>::max();
  // Per sample: presence, and its accepted candidates (several only transiently, while
  // higher ranks wait to be re-decided): how many and the lowest rank.
  struct Side {
    int32_t min_accepted = kNone, n_accepted = 0;
    bool in = false;
  };

  // Only a candidate whose other side is in changes presence; one leaving matters only
  // if it was accepted.
  void set(std::vector<Side>& self, const std::vector<Side>& other, const RanksBy& by, int32_t x, bool value) {
    if (self[x].in == value) return;
    self[x].in = value;
    if (!value && self[x].n_accepted == 0) return;
    if (!value && self[x].n_accepted == 1) {  // the usual case: x's one accepted candidate
      const int32_t rank = self[x].min_accepted;
      const int32_t y = &self == &g_ ? pair_[rank].second : pair_[rank].first;
      if (other[y].in) push(rank);
      return;
    }
    meter_.spend(by.offset[x + 1] - by.offset[x]);
    for (int32_t k = by.offset[x]; k < by.offset[x + 1]; ++k) {
      const RanksBy::Entry e = by.entries[k];
      if (!other[e.other].in) continue;
      if (value || accepted_[e.rank]) push(e.rank);
    }
  }
  // After x's candidate `rank` flipped: newly accepted, the accepted candidates above it
  // on x (if any) can lose; newly rejected, the present rejected ones above it can win,
  // unless x keeps an accepted candidate below (they stay rejected then).
  void push_above(const RanksBy& by, int32_t x, int32_t rank, bool accepted_now, const std::vector<Side>& self,
                  const std::vector<Side>& other) {
    if (accepted_now ? self[x].n_accepted < 2 : self[x].min_accepted < rank) return;
    for (int32_t k = by.offset[x + 1] - 1; k >= by.offset[x] && by.entries[k].rank > rank; --k) {
      meter_.spend(1);
      const RanksBy::Entry e = by.entries[k];
      const bool present = self[x].in && other[e.other].in;
      if (accepted_now ? accepted_[e.rank] != 0 : (accepted_[e.rank] == 0 && present)) push(e.rank);
    }
  }
  void push(int32_t rank) {
    const size_t wi = static_cast<size_t>(rank) >> 6;
    pending_[wi] |= uint64_t{1} << (rank & 63);
    const size_t si = wi >> 6;
    summary_[si] |= uint64_t{1} << (wi & 63);
    lo_ = std::min(lo_, si);
    hi_ = std::max(hi_, si + 1);
  }
  void accept(Side& s, int32_t rank) {
    ++s.n_accepted;
    s.min_accepted = std::min(s.min_accepted, rank);
  }
  void reject(Side& s, const RanksBy& by, int32_t x, int32_t rank) {
    --s.n_accepted;
    if (s.min_accepted != rank) return;
    s.min_accepted = kNone;
    if (s.n_accepted == 0) return;
    for (int32_t k = by.offset[x]; k < by.offset[x + 1]; ++k) {
      meter_.spend(1);
      if (accepted_[by.entries[k].rank]) {
        s.min_accepted = by.entries[k].rank;
        break;
      }
    }
  }
  void decide(int32_t rank) {
    meter_.spend(1);
    const auto [g, p] = pair_[rank];
    // No accepted candidate below `rank` on g nor on p.
    const uint8_t now = g_[g].in && p_[p].in && g_[g].min_accepted >= rank && p_[p].min_accepted >= rank;
    if (now == accepted_[rank]) return;
    accepted_[rank] = now;
    if (now) {
      ++m_;
      accept(g_[g], rank);
      accept(p_[p], rank);
    } else {
      --m_;
      reject(g_[g], by_g_, g, rank);
      reject(p_[p], by_p_, p, rank);
    }
    push_above(by_g_, g, rank, now != 0, g_, p_);
    push_above(by_p_, p, rank, now != 0, p_, g_);
  }

  WorkMeter& meter_;
  const RanksBy& by_g_;
  const RanksBy& by_p_;
  std::vector<std::pair<int32_t, int32_t>> pair_;  // (g, p) by rank
  std::vector<uint8_t> accepted_;
  std::vector<Side> g_, p_;
  std::vector<uint64_t> pending_;  // ranks to re-decide
  std::vector<uint64_t> summary_;  // words of pending_ that may be non-zero
  size_t lo_ = 0, hi_ = 0;         // words of summary_ that may be non-zero
  int64_t m_ = 0;
};

// Seed indices in visiting order: grouped by the connected components of g and of p (a
// seed whose p lies on another component than its neighbours' would swap the whole
// predicted reach set out and back), and within a group by a walk of the GT sample graph
// chain by chain (a, interior samples, b), so that consecutive seeds are neighbours.
std::vector<int32_t> visit_order(const SampleGraph& gt, const SampleGraph& pred,
                                 const std::vector<std::pair<int32_t, int32_t>>& seeds) {
  std::vector<int32_t> pos_of(gt.size(), -1);
  int32_t next = 0;
  auto visit = [&](int32_t x) {
    if (pos_of[x] < 0) pos_of[x] = next++;
  };
  for (const Chain& c : gt.chains) {
    visit(c.a);
    for (int32_t k = 0; k + 1 < c.k; ++k) visit(c.first + k);
    visit(c.b);
  }
  std::vector<std::array<int32_t, 4>> keys(seeds.size());
  for (size_t s = 0; s < seeds.size(); ++s) {
    const auto [g, p] = seeds[s];
    keys[s] = {gt.comp[g], pred.comp[p], pos_of[g], static_cast<int32_t>(s)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<int32_t> order(seeds.size());
  for (size_t s = 0; s < seeds.size(); ++s) order[s] = keys[s][3];
  return order;
}

// Undirected shortcut: when the last search (from `anchor`) reached the anchor's whole
// connected component, a new source x in it reaches the whole component too if
// d(anchor, x) + max_y d(anchor, y) stays below the radius (triangle inequality), with a
// margin far above the rounding of the path sums; its reach set is then unchanged and
// the search is skipped.
class WholeComponent {
 public:
  WholeComponent(const SampleGraph& sg, double radius_px)
      : limit_(radius_px - kMarginPx), comp_(sg.comp), size_(sg.size(), 0) {
    for (int32_t c : comp_) ++size_[c];
  }
  bool still_whole(const RadiusSearch& last, int32_t x) const {
    return whole_ && comp_[x] == comp_[anchor_] && last.dist_to(x) + last.max_dist() <= limit_;
  }
  // Records a search from `src` that reached `n_reached` samples.
  void ran(int32_t src, int64_t n_reached) {
    anchor_ = src;
    whole_ = n_reached == static_cast<int64_t>(size_[comp_[src]]);
  }

 private:
  static constexpr double kMarginPx = 1e-6;
  double limit_;
  const std::vector<int32_t>& comp_;
  std::vector<int32_t> size_;
  int32_t anchor_ = -1;
  bool whole_ = false;
};

// Rules 6-8 on the undirected or the directed sample graphs: each seed's p_s and r_s, by
// seed index (seeds in increasing g).
SeedTopo topo_per_seed(const SampleGraph& gt, const SampleGraph& pred, bool directed,
                       const std::vector<Candidate>& cands, const RanksBy& by_g, const RanksBy& by_p,
                       const std::vector<std::pair<int32_t, int32_t>>& seeds, const std::vector<int32_t>& order,
                       double radius_px, WorkMeter& meter) {
  RadiusSearch search_g(gt, meter), search_p(pred, meter);
  IncrementalMatching matching(cands, by_g, by_p, meter);
  // Seeds are visited in `order` (consecutive reach sets then differ little) and summed
  // afterwards in increasing g, as rule 7 adds them.
  std::vector<int64_t> m_of(seeds.size(), 0), n_rp(seeds.size(), 0), n_rg(seeds.size(), 0);
  WholeComponent whole_g(gt, radius_px), whole_p(pred, radius_px);
  for (size_t o = 0; o < order.size(); ++o) {
    const int32_t s = order[o];
    if (directed || !whole_p.still_whole(search_p, seeds[s].second)) {
      search_p.run(seeds[s].second, directed, radius_px);
      search_p.diff([&](int32_t x, bool in) {
        meter.spend(1);
        matching.set_p(x, in);
      });
      whole_p.ran(seeds[s].second, search_p.count());
    }
    if (directed || !whole_g.still_whole(search_g, seeds[s].first)) {
      search_g.run(seeds[s].first, directed, radius_px);
      search_g.diff([&](int32_t x, bool in) {
        meter.spend(1);
        matching.set_g(x, in);
      });
      whole_g.ran(seeds[s].first, search_g.count());
    }
    m_of[s] = matching.matched();
    n_rp[s] = search_p.count();
    n_rg[s] = search_g.count();
  }
  SeedTopo out;
  out.p.resize(seeds.size());
  out.r.resize(seeds.size());
  for (size_t s = 0; s < seeds.size(); ++s) {
    const auto m = static_cast<double>(m_of[s]);
    out.p[s] = m / static_cast<double>(n_rp[s]);
    out.r[s] = m / static_cast<double>(n_rg[s]);
  }
  return out;
}

}  // namespace

GeoTopoResult compute_geo_topo(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params,
                               WorkMeter& meter) {
  const SampleGraph g = sample_graph(gt, params.geo_step_px);
  const SampleGraph p = sample_graph(pred, params.geo_step_px);
  GeoTopoResult r;
  r.gt_samples = static_cast<int64_t>(g.size());
  r.pred_samples = static_cast<int64_t>(p.size());

  // Rule 4/5: greedy one-to-one GEO matching.
  const std::vector<Candidate> cands = candidates(g, p, params.geo_match_px);
  std::vector<int32_t> match_of_g(g.size(), -1);
  std::vector<uint8_t> p_used(p.size(), 0);
  const RanksBy by_g = ranks_by(g.size(), cands, true), by_p = ranks_by(p.size(), cands, false);
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
  const std::vector<int32_t> order = visit_order(g, p, seeds);
  const SeedTopo und = topo_per_seed(g, p, false, cands, by_g, by_p, seeds, order, radius_px, meter);
  const SeedTopo dir = topo_per_seed(g, p, true, cands, by_g, by_p, seeds, order, radius_px, meter);
  const auto all = [](size_t) { return true; };
  r.topo_precision = ratio(seed_sum(und.p, all), np);
  r.topo_recall = ratio(seed_sum(und.r, all), ng);
  r.topo_f1 = f1_of(r.topo_precision, r.topo_recall);
  r.topo_directed_precision = ratio(seed_sum(dir.p, all), np);
  r.topo_directed_recall = ratio(seed_sum(dir.r, all), ng);
  r.topo_directed_f1 = f1_of(r.topo_directed_precision, r.topo_directed_recall);
  set_junction_topo(gt, g, seeds, dir, r);
  set_class_recalls(g, match_of_g, seeds, und, r);
  return r;
}

}  // namespace nsg::metrics::detail
