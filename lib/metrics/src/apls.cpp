// APLS as the SpaceNet reference computes it, with its snapping defect fixed
// (docs/metrics.md "APLS"): A's nodes snap onto B's nearest segment, which is split at the
// projections, and path lengths between control-point pairs are compared.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "internal.h"
#include "spatial.h"

namespace nsg::metrics::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Projections this close (metres along the segment) to an end node are that node, and
// this close to each other share one node (docs/metrics.md rule 3, version 2): a control
// point a centimetre off a junction node — a rounded or re-projected copy — reaches every
// lane of the junction as the node does. (Version 1 compared t within 1e-12, so such a
// point split an incoming lane next to the node and lost every path through it.)
constexpr double kSameSpotM = 0.01;

struct Pm {
  double x = 0.0, y = 0.0;  // metres
};

std::vector<Pm> to_metres(const CleanGraph& g, double resolution_m) {
  std::vector<Pm> out;
  out.reserve(g.nodes.size());
  for (const Point& p : g.nodes) out.push_back({p.u * resolution_m, p.v * resolution_m});
  return out;
}

double dist_m(const Pm& a, const Pm& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  return std::sqrt(dx * dx + dy * dy);
}

struct Arc {
  int32_t from, to;
  double w;
};

// Compressed adjacency for Dijkstra.
class PathGraph {
 public:
  PathGraph(size_t n, const std::vector<Arc>& arcs) : offset_(n + 1, 0) {
    for (const Arc& a : arcs) ++offset_[a.from + 1];
    for (size_t k = 0; k < n; ++k) offset_[k + 1] += offset_[k];
    to_.resize(arcs.size());
    w_.resize(arcs.size());
    std::vector<int32_t> fill(offset_.begin(), offset_.end() - 1);
    for (const Arc& a : arcs) {
      to_[fill[a.from]] = a.to;
      w_[fill[a.from]++] = a.w;
    }
  }
  size_t size() const { return offset_.size() - 1; }

  // Shortest path lengths from `src`: `dist` (size() entries, kInf where unreachable)
  // is reset through `reached`, the nodes it reached last time, which this call
  // overwrites (unsorted). `heap` is scratch space. The search stops once every node
  // within `max_m` is final: a node farther keeps an upper bound (> max_m) or kInf.
  void shortest_paths(int32_t src, std::vector<double>& dist, std::vector<int32_t>& reached,
                      std::vector<std::pair<double, int32_t>>& heap, WorkMeter& meter, double max_m = kInf) const {
    if (dist.size() != size()) dist.assign(size(), kInf);
    for (int32_t n : reached) dist[n] = kInf;
    reached.clear();
    heap.clear();
    dist[src] = 0.0;
    reached.push_back(src);
    heap.push_back({0.0, src});
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end(), std::greater<>());
      const auto [d, n] = heap.back();
      if (d > max_m) break;
      heap.pop_back();
      if (d > dist[n]) continue;
      // A settled node and each relaxation cost about twice a TOPO step (heap operations).
      meter.spend(2 * (1 + offset_[n + 1] - offset_[n]));
      for (int32_t k = offset_[n]; k < offset_[n + 1]; ++k) {
        const double nd = d + w_[k];
        if (nd < dist[to_[k]]) {
          if (dist[to_[k]] == kInf) reached.push_back(to_[k]);
          dist[to_[k]] = nd;
          heap.push_back({nd, to_[k]});
          std::push_heap(heap.begin(), heap.end(), std::greater<>());
        }
      }
    }
  }

 private:
  std::vector<int32_t> offset_;
  std::vector<int32_t> to_;
  std::vector<double> w_;
};

void add_piece(std::vector<Arc>& arcs, int32_t a, int32_t b, double w, bool fwd, bool bwd) {
  if (fwd) arcs.push_back({a, b, w});
  if (bwd) arcs.push_back({b, a, w});
}

PathGraph graph_paths(const std::vector<Pm>& nodes, const std::vector<Segment>& segs, bool directed) {
  std::vector<Arc> arcs;
  for (const Segment& s : segs) {
    const double w = dist_m(nodes[s.i], nodes[s.j]);
    add_piece(arcs, s.i, s.j, w, !directed || s.fwd, !directed || s.bwd);
  }
  return PathGraph(nodes.size(), arcs);
}

// Nearest segment of B for one control point of A (ties: smallest (i, j), i.e. first),
// among the segments within `reach_m`; seg = -1 if there is none (the point is then
// unmatched at every snap radius <= reach_m, as with an all-pairs scan).
struct Snap {
  int32_t seg = -1;
  double d_m = kInf;
  double t = 0.0;
};

std::vector<Snap> snap_all(const std::vector<Pm>& a_nodes, const std::vector<Pm>& b_nodes,
                           const std::vector<Segment>& b_segs, double reach_m) {
  std::vector<SegmentGrid::Box> boxes;
  boxes.reserve(b_segs.size());
  for (const Segment& s : b_segs) {
    const Pm a = b_nodes[s.i], b = b_nodes[s.j];
    boxes.push_back({std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y)});
  }
  // The margin covers the rounding of the distance: every segment that can be within
  // reach_m is listed, and the candidates are visited in increasing index as before.
  const SegmentGrid grid(boxes, reach_m + 1e-6);
  std::vector<Snap> snaps(a_nodes.size());
  for (size_t n = 0; n < a_nodes.size(); ++n) {
    const Pm p = a_nodes[n];
    Snap best;
    const auto [first, last] = grid.near(p.x, p.y);
    for (const int32_t* k = first; k != last; ++k) {
      const Pm a = b_nodes[b_segs[*k].i], b = b_nodes[b_segs[*k].j];
      const SegmentDistance sd = point_segment(p.x, p.y, a.x, a.y, b.x, b.y);
      const double d = std::sqrt(sd.d2);
      if (d < best.d_m) best = {*k, d, sd.t};
    }
    snaps[n] = best;
  }
  return snaps;
}

// B' = B with its segments split at the matched projections; node_of[a] is the B' node of
// control point a (-1 if unmatched).
struct SplitGraph {
  std::vector<Arc> arcs;
  size_t n_nodes = 0;
  std::vector<int32_t> node_of;
};

SplitGraph split_at_snaps(const std::vector<Pm>& b_nodes, const std::vector<Segment>& b_segs,
                          const std::vector<Snap>& snaps, double snap_m, bool directed) {
  SplitGraph out;
  out.node_of.assign(snaps.size(), -1);
  std::vector<std::vector<std::pair<double, int32_t>>> on_seg(b_segs.size());
  for (size_t a = 0; a < snaps.size(); ++a) {
    if (snaps[a].seg >= 0 && snaps[a].d_m <= snap_m)
      on_seg[snaps[a].seg].push_back({snaps[a].t, static_cast<int32_t>(a)});
  }
  int32_t next = static_cast<int32_t>(b_nodes.size());
  for (size_t k = 0; k < b_segs.size(); ++k) {
    const Segment& s = b_segs[k];
    const Pm pa = b_nodes[s.i], pb = b_nodes[s.j];
    const bool fwd = !directed || s.fwd, bwd = !directed || s.bwd;
    auto& pts = on_seg[k];
    std::sort(pts.begin(), pts.end());
    const double len_m = dist_m(pa, pb);
    // Chain of nodes from the i end to the j end, with their positions.
    struct Link {
      int32_t node;
      double at_m;  // along the segment from the i end
      Pm pos;
    };
    std::vector<Link> chain{{s.i, 0.0, pa}};
    for (const auto& [t, a] : pts) {
      const double at_m = t * len_m, to_j_m = (1.0 - t) * len_m;
      if (at_m <= kSameSpotM && at_m <= to_j_m) {
        out.node_of[a] = s.i;
      } else if (to_j_m <= kSameSpotM) {
        out.node_of[a] = s.j;
      } else {
        if (chain.size() == 1 || at_m - chain.back().at_m > kSameSpotM)
          chain.push_back({next++, at_m, {pa.x + t * (pb.x - pa.x), pa.y + t * (pb.y - pa.y)}});
        out.node_of[a] = chain.back().node;
      }
    }
    chain.push_back({s.j, len_m, pb});
    for (size_t c = 0; c + 1 < chain.size(); ++c)
      add_piece(out.arcs, chain[c].node, chain[c + 1].node, dist_m(chain[c].pos, chain[c + 1].pos), fwd, bwd);
  }
  out.n_nodes = static_cast<size_t>(next);
  return out;
}

bool same_split(const SplitGraph& x, const SplitGraph& y) {
  auto same_arc = [](const Arc& p, const Arc& q) { return p.from == q.from && p.to == q.to && p.w == q.w; };
  return x.n_nodes == y.n_nodes && x.node_of == y.node_of &&
         std::equal(x.arcs.begin(), x.arcs.end(), y.arcs.begin(), y.arcs.end(), same_arc);
}

struct OneSided {
  int64_t pairs = 0;
  double cost_sum = 0.0;
  std::optional<double> value() const {
    if (pairs == 0) return std::nullopt;
    return 1.0 - cost_sum / static_cast<double>(pairs);
  }
};

// C(A -> B) before the final 1 - mean, for each snap radius of `snap_ms` (the variants
// share A's shortest paths, computed once per control point).
std::vector<OneSided> one_sided(const std::vector<Pm>& a_nodes, const std::vector<Segment>& a_segs,
                                const std::vector<Pm>& b_nodes, const std::vector<Segment>& b_segs,
                                const std::vector<Snap>& snaps, const std::vector<double>& snap_ms, bool directed,
                                double min_path_m, WorkMeter& meter) {
  const PathGraph a_graph = graph_paths(a_nodes, a_segs, directed);
  std::vector<SplitGraph> splits;
  std::vector<PathGraph> b_graphs;
  for (double snap_m : snap_ms) {
    splits.push_back(split_at_snaps(b_nodes, b_segs, snaps, snap_m, directed));
    b_graphs.emplace_back(splits.back().n_nodes, splits.back().arcs);
  }
  // A snap radius that changes no snap (every snap within both) gives the same split
  // graph: its shortest paths are then those of the first such variant.
  std::vector<size_t> same_as(snap_ms.size());
  for (size_t v = 0; v < snap_ms.size(); ++v) {
    same_as[v] = v;
    for (size_t u = 0; u < v && same_as[v] == v; ++u)
      if (same_split(splits[u], splits[v])) same_as[v] = u;
  }
  std::vector<OneSided> out(snap_ms.size());
  std::vector<double> dist_a;
  std::vector<int32_t> reached_a;
  std::vector<std::vector<double>> dist_b(snap_ms.size());  // one per split graph
  std::vector<std::vector<int32_t>> reached_b(snap_ms.size());
  std::vector<uint8_t> have_b(snap_ms.size());  // dist_b[v] is from this round's a
  std::vector<std::pair<double, int32_t>> heap;
  const auto n = static_cast<int32_t>(a_nodes.size());
  for (int32_t a = 0; a < n; ++a) {
    // Only nodes with a finite path count; visit them in increasing index as the mean's
    // sum is defined.
    a_graph.shortest_paths(a, dist_a, reached_a, heap, meter);
    std::sort(reached_a.begin(), reached_a.end());
    meter.spend(static_cast<int64_t>(reached_a.size()));  // the sort
    // A pair costs 1 once the other graph's path is >= 2 x its own (|la - lb| / la >= 1,
    // also in rounded arithmetic), so the other graph is searched only that far: the
    // same costs, and a short piece of one graph no longer pays for a search of the
    // other graph's whole connected piece.
    double max_la = 0.0;
    for (int32_t b : reached_a) max_la = std::max(max_la, dist_a[b]);
    std::fill(have_b.begin(), have_b.end(), 0);
    for (size_t v = 0; v < snap_ms.size(); ++v) {
      const SplitGraph& split = splits[v];
      const size_t u = same_as[v];
      OneSided& r = out[v];
      for (int32_t b : reached_a) {
        const double la = dist_a[b];
        if (b == a || la < min_path_m) continue;
        ++r.pairs;
        if (split.node_of[a] < 0 || split.node_of[b] < 0) {
          r.cost_sum += 1.0;
          continue;
        }
        if (!have_b[u]) {
          b_graphs[u].shortest_paths(split.node_of[a], dist_b[u], reached_b[u], heap, meter, 2.0 * max_la);
          have_b[u] = 1;
        }
        const double lb = dist_b[u][split.node_of[b]];
        r.cost_sum += lb > 2.0 * la ? 1.0 : std::min(1.0, std::abs(la - lb) / la);
      }
    }
  }
  return out;
}

AplsResult combine(const OneSided& gt_to_pred, const OneSided& pred_to_gt) {
  AplsResult r;
  r.gt_pairs = gt_to_pred.pairs;
  r.pred_pairs = pred_to_gt.pairs;
  r.gt_to_pred = gt_to_pred.value();
  r.pred_to_gt = pred_to_gt.value();
  if (!r.gt_to_pred) return r;  // undefined: the GT has no evaluable pair
  if (!r.pred_to_gt) {
    r.apls = 0.0;
    return r;
  }
  const double c1 = *r.gt_to_pred, c2 = *r.pred_to_gt;
  r.apls = (c1 <= 0.0 || c2 <= 0.0) ? 0.0 : 2.0 * c1 * c2 / (c1 + c2);
  return r;
}

}  // namespace

AplsFamily compute_apls(const CleanGraph& gt, const CleanGraph& pred, const MetricParams& params, WorkMeter& meter) {
  const std::vector<Pm> g = to_metres(gt, params.resolution_m);
  const std::vector<Pm> p = to_metres(pred, params.resolution_m);
  const std::vector<Segment> g_segs = segments_of(gt), p_segs = segments_of(pred);
  // The nearest segment does not depend on the variant: snap once per direction.
  const double reach_m = std::max(params.snap_m, params.strict_snap_m);
  const std::vector<Snap> g_on_p = snap_all(g, p, p_segs, reach_m);
  const std::vector<Snap> p_on_g = snap_all(p, g, g_segs, reach_m);
  // Undirected: the normal and the strict snap radius; directed: the normal one.
  auto sides = [&](const std::vector<double>& snap_ms, bool directed) {
    return std::pair{one_sided(g, g_segs, p, p_segs, g_on_p, snap_ms, directed, params.min_path_m, meter),
                     one_sided(p, p_segs, g, g_segs, p_on_g, snap_ms, directed, params.min_path_m, meter)};
  };
  const auto [und_gp, und_pg] = sides({params.snap_m, params.strict_snap_m}, false);
  const auto [dir_gp, dir_pg] = sides({params.snap_m}, true);
  AplsFamily f;
  f.undirected = combine(und_gp[0], und_pg[0]);
  f.directed = combine(dir_gp[0], dir_pg[0]);
  f.strict = combine(und_gp[1], und_pg[1]);
  return f;
}

}  // namespace nsg::metrics::detail
