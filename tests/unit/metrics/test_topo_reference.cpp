// The fast paths of measure() against straightforward references written from
// docs/metrics.md on small random graphs. GEO/TOPO (its numbered rules): explicit sample graph, plain
// Dijkstra from every seed, restricted candidate list re-scanned greedily. APLS: all
// pairs by Floyd-Warshall on A and on the split B', every ordered pair visited.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <tuple>
#include <vector>

#include "nsg/core/rng.h"
#include "nsg/metrics/graph.h"
#include "nsg/metrics/measure.h"

namespace nsg::metrics {
namespace {

struct Arc {
  int32_t to;
  double w;
};

struct RefSamples {
  std::vector<Point> pos;
  std::vector<std::vector<Arc>> und, dir;  // sample graph (rule 3)
};

RefSamples ref_samples(const Graph& graph, double step_px) {
  const CleanGraph g = clean_graph(graph);
  const std::vector<Segment> segs = segments_of(g);
  RefSamples r;
  std::vector<int32_t> id(g.nodes.size(), -1);
  for (const Segment& s : segs) id[s.i] = id[s.j] = 0;
  for (size_t n = 0; n < g.nodes.size(); ++n) {
    if (id[n] < 0) continue;
    id[n] = static_cast<int32_t>(r.pos.size());
    r.pos.push_back(g.nodes[n]);
  }
  std::vector<std::tuple<int32_t, int32_t, double, bool, bool>> pieces;
  for (const Segment& s : segs) {
    const Point a = g.nodes[s.i], b = g.nodes[s.j];
    const double dx = b.u - a.u, dy = b.v - a.v, len = std::sqrt(dx * dx + dy * dy);
    // Rule 2 as of metrics version 3: a segment up to 0.05 steps over k steps stays k pieces.
    const int k = std::max(1, static_cast<int>(std::ceil(len / step_px - 0.05)));
    int32_t prev = id[s.i];
    for (int q = 1; q < k; ++q) {
      const double t = static_cast<double>(q) / k;
      const auto cur = static_cast<int32_t>(r.pos.size());
      r.pos.push_back({a.u + dx * t, a.v + dy * t});
      pieces.emplace_back(prev, cur, len / k, s.fwd, s.bwd);
      prev = cur;
    }
    pieces.emplace_back(prev, id[s.j], len / k, s.fwd, s.bwd);
  }
  r.und.resize(r.pos.size());
  r.dir.resize(r.pos.size());
  for (const auto& [a, b, w, fwd, bwd] : pieces) {
    r.und[a].push_back({b, w});
    r.und[b].push_back({a, w});
    if (fwd) r.dir[a].push_back({b, w});
    if (bwd) r.dir[b].push_back({a, w});
  }
  return r;
}

std::vector<bool> within(const std::vector<std::vector<Arc>>& adj, int32_t src, double radius) {
  std::vector<double> dist(adj.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  dist[src] = 0.0;
  heap.push({0.0, src});
  while (!heap.empty()) {
    const auto [d, n] = heap.top();
    heap.pop();
    if (d > dist[n]) continue;
    for (const Arc& a : adj[n]) {
      if (d + a.w < dist[a.to]) {
        dist[a.to] = d + a.w;
        heap.push({dist[a.to], a.to});
      }
    }
  }
  std::vector<bool> in(adj.size());
  for (size_t k = 0; k < adj.size(); ++k) in[k] = dist[k] <= radius;
  return in;
}

struct RefTopo {
  int64_t ng = 0, np = 0, matched = 0;
  double und_p = 0, und_r = 0, dir_p = 0, dir_r = 0;  // sums over seeds
};

RefTopo reference(const Graph& gt, const Graph& pred, const MetricParams& params) {
  const RefSamples g = ref_samples(gt, params.geo_step_px);
  const RefSamples p = ref_samples(pred, params.geo_step_px);
  std::vector<std::tuple<int64_t, int32_t, int32_t>> cands;
  const auto q_max = static_cast<int64_t>(std::floor(params.geo_match_px * params.geo_match_px * 1e6 + 0.5));
  for (size_t a = 0; a < g.pos.size(); ++a) {
    for (size_t b = 0; b < p.pos.size(); ++b) {
      const double dx = g.pos[a].u - p.pos[b].u, dy = g.pos[a].v - p.pos[b].v;
      const auto q = static_cast<int64_t>(std::floor((dx * dx + dy * dy) * 1e6 + 0.5));
      if (q <= q_max) cands.emplace_back(q, static_cast<int32_t>(a), static_cast<int32_t>(b));
    }
  }
  std::sort(cands.begin(), cands.end());
  auto greedy = [&](const std::vector<bool>* in_g, const std::vector<bool>* in_p, std::vector<int32_t>* match_of_g) {
    std::vector<bool> used_g(g.pos.size()), used_p(p.pos.size());
    int64_t m = 0;
    for (const auto& [q, a, b] : cands) {
      if ((in_g && !(*in_g)[a]) || (in_p && !(*in_p)[b]) || used_g[a] || used_p[b]) continue;
      used_g[a] = used_p[b] = true;
      if (match_of_g) (*match_of_g)[a] = b;
      ++m;
    }
    return m;
  };
  RefTopo r;
  r.ng = static_cast<int64_t>(g.pos.size());
  r.np = static_cast<int64_t>(p.pos.size());
  std::vector<int32_t> match_of_g(g.pos.size(), -1);
  r.matched = greedy(nullptr, nullptr, &match_of_g);
  const double radius = params.topo_radius_m / params.resolution_m + 1e-6;
  for (size_t a = 0; a < g.pos.size(); ++a) {
    if (match_of_g[a] < 0) continue;
    for (bool directed : {false, true}) {
      const auto in_g = within(directed ? g.dir : g.und, static_cast<int32_t>(a), radius);
      const auto in_p = within(directed ? p.dir : p.und, match_of_g[a], radius);
      const auto m = static_cast<double>(greedy(&in_g, &in_p, nullptr));
      const auto n_g = static_cast<double>(std::count(in_g.begin(), in_g.end(), true));
      const auto n_p = static_cast<double>(std::count(in_p.begin(), in_p.end(), true));
      (directed ? r.dir_p : r.und_p) += m / n_p;
      (directed ? r.dir_r : r.und_r) += m / n_g;
    }
  }
  return r;
}

// Lane-like random graphs: a few polylines (some edges reversed or two-way, some joined),
// on an integer grid half of the time so that distance ties are frequent.
Graph random_graph(Rng& rng, bool grid) {
  Graph g;
  const int lanes = static_cast<int>(rng.uniform_int(int64_t{1}, int64_t{4}));
  for (int l = 0; l < lanes; ++l) {
    const auto first = static_cast<int64_t>(g.nodes.size());
    double u = rng.uniform(0, 120), v = rng.uniform(0, 120), angle = rng.uniform(0, 6.3);
    const int n = static_cast<int>(rng.uniform_int(int64_t{2}, int64_t{9}));
    for (int k = 0; k < n; ++k) {
      g.nodes.push_back(grid ? Point{std::round(u), std::round(v)} : Point{u, v});
      const double step = rng.uniform(1.0, 14.0);
      u += step * std::cos(angle);
      v += step * std::sin(angle);
      angle += rng.uniform(-0.5, 0.5);
      if (k == 0) continue;
      const int64_t i = first + k - 1, j = first + k;
      if (rng.bernoulli(0.8)) g.edges.push_back({i, j});
      if (rng.bernoulli(0.3)) g.edges.push_back({j, i});
    }
    if (first > 0 && rng.bernoulli(0.5))
      g.edges.push_back({first, static_cast<int64_t>(rng.uniform_int(static_cast<uint64_t>(first)))});
  }
  return g;
}

Graph perturbed(Rng& rng, const Graph& g, double sigma_px) {
  Graph out = g;
  for (Point& p : out.nodes) {
    p.u += sigma_px * rng.normal();
    p.v += sigma_px * rng.normal();
  }
  if (!out.edges.empty() && rng.bernoulli(0.3)) out.edges.pop_back();
  return out;
}

void expect_ratio(const std::optional<double>& got, double num, double den, const char* name, int trial) {
  if (den == 0.0) {
    EXPECT_FALSE(got.has_value()) << name << " trial " << trial;
    return;
  }
  ASSERT_TRUE(got.has_value()) << name << " trial " << trial;
  EXPECT_NEAR(*got, num / den, 1e-12) << name << " trial " << trial;
}

// The fast path's counts and GEO/TOPO values against the reference of one trial; false
// (stop the trial loop) when the sample counts already disagree.
bool expect_matches_reference(const TileMeasurement& t, const RefTopo& r, int trial) {
  EXPECT_EQ(t.counts[kGeoGtSamples], r.ng) << "trial " << trial;
  EXPECT_EQ(t.counts[kGeoPredSamples], r.np) << "trial " << trial;
  EXPECT_EQ(t.counts[kGeoMatched], r.matched) << "trial " << trial;
  if (t.counts[kGeoGtSamples] != r.ng || t.counts[kGeoPredSamples] != r.np || t.counts[kGeoMatched] != r.matched)
    return false;
  const auto ng = static_cast<double>(r.ng), np = static_cast<double>(r.np);
  expect_ratio(t.values[kGeoPrecision], static_cast<double>(r.matched), np, "geo_p", trial);
  expect_ratio(t.values[kTopoPrecision], r.und_p, np, "topo_p", trial);
  expect_ratio(t.values[kTopoRecall], r.und_r, ng, "topo_r", trial);
  expect_ratio(t.values[kTopoDirectedPrecision], r.dir_p, np, "topo_dir_p", trial);
  expect_ratio(t.values[kTopoDirectedRecall], r.dir_r, ng, "topo_dir_r", trial);
  return true;
}

TEST(TopoReference, FastPathMatchesStraightforwardDefinition) {
  Rng rng(2024);
  int nontrivial = 0;
  for (int trial = 0; trial < 300; ++trial) {
    MetricParams params;
    // Small radii make reach sets cut through the graphs; the default 40 m covers them.
    params.topo_radius_m = trial % 3 == 0 ? 40.0 : rng.uniform(0.5, 8.0);
    const bool grid = trial % 2 == 0;
    const Graph gt = random_graph(rng, grid);
    const Graph pred =
        trial % 5 == 0 ? random_graph(rng, grid) : perturbed(rng, gt, grid ? 0.0 : rng.uniform(0.0, 3.0));
    const TileMeasurement t = measure("k", gt, &pred, params);
    const RefTopo r = reference(gt, pred, params);
    if (!expect_matches_reference(t, r, trial)) return;
    if (r.matched > 0 && r.und_p < static_cast<double>(r.matched) && r.dir_p < r.und_p) ++nontrivial;
  }
  // The cases must exercise partial reach sets, not only perfect matches.
  EXPECT_GT(nontrivial, 30);
}

// Street lattices with one-way, two-way and missing links (many cycles, so chains are
// reached from both ends and walked from both), or crossing lanes that do not connect
// (seeds whose prediction lies on another component than their neighbours').
Graph lattice_or_crossing(Rng& rng, bool grid) {
  Graph g;
  auto node = [&](double u, double v) {
    g.nodes.push_back(grid ? Point{std::round(u), std::round(v)} : Point{u, v});
    return static_cast<int64_t>(g.nodes.size() - 1);
  };
  if (rng.bernoulli(0.5)) {
    const int rows = static_cast<int>(rng.uniform_int(int64_t{2}, int64_t{5}));
    const int cols = static_cast<int>(rng.uniform_int(int64_t{2}, int64_t{5}));
    const double step = rng.uniform(4.0, 30.0);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) node(c * step + rng.uniform(-1, 1), r * step + rng.uniform(-1, 1));
    auto link = [&](int64_t i, int64_t j) {
      const double x = rng.uniform(0, 1);
      if (x < 0.4) g.edges.push_back({i, j});
      else if (x < 0.7) g.edges.push_back({j, i});
      else if (x < 0.9) g.edges.insert(g.edges.end(), {{i, j}, {j, i}});
    };
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const int64_t k = r * cols + c;
        if (c + 1 < cols) link(k, k + 1);
        if (r + 1 < rows) link(k, k + cols);
      }
  } else {
    const int lanes = static_cast<int>(rng.uniform_int(int64_t{2}, int64_t{6}));
    for (int l = 0; l < lanes; ++l) {
      const bool across = l % 2 == 0;
      const double off = rng.uniform(20, 100), len = rng.uniform(60, 140);
      const int n = static_cast<int>(rng.uniform_int(int64_t{2}, int64_t{8}));
      const int64_t first = static_cast<int64_t>(g.nodes.size());
      for (int k = 0; k < n; ++k) {
        const double t = len * k / (n - 1);
        across ? node(t, off) : node(off, t);
        if (k > 0) g.edges.push_back({first + k - 1, first + k});
      }
    }
  }
  return g;
}

TEST(TopoReference, LatticesAndCrossingLanesMatchDefinition) {
  Rng rng(909);
  int nontrivial = 0;
  for (int trial = 0; trial < 150; ++trial) {
    MetricParams params;
    params.topo_radius_m = trial % 3 == 0 ? 40.0 : rng.uniform(1.0, 12.0);
    const bool grid = trial % 2 == 0;
    const Graph gt = lattice_or_crossing(rng, grid);
    const Graph pred =
        trial % 4 == 0 ? lattice_or_crossing(rng, grid) : perturbed(rng, gt, grid ? 0.0 : rng.uniform(0.0, 4.0));
    const TileMeasurement t = measure("k", gt, &pred, params);
    const RefTopo r = reference(gt, pred, params);
    if (!expect_matches_reference(t, r, trial)) return;
    if (r.matched > 0 && r.und_p < static_cast<double>(r.matched) && r.dir_p < r.und_p) ++nontrivial;
  }
  EXPECT_GT(nontrivial, 30);
}

// ---- APLS reference -------------------------------------------------------------------

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Pm {
  double x, y;
};

double seg_dist(Pm p, Pm a, Pm b, double* t_out) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  double t = 0.0;
  if (len2 > 0.0) t = std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0);
  const double qx = a.x + t * dx - p.x, qy = a.y + t * dy - p.y;
  *t_out = t;
  return std::sqrt(qx * qx + qy * qy);
}

using Matrix = std::vector<std::vector<double>>;

void floyd(Matrix& d) {
  const size_t n = d.size();
  for (size_t k = 0; k < n; ++k) {
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = 0; j < n; ++j) {
        if (d[i][k] + d[k][j] < d[i][j]) d[i][j] = d[i][k] + d[k][j];
      }
    }
  }
}

void add_arc(Matrix& d, size_t a, size_t b, double w, bool fwd, bool bwd) {
  if (fwd) d[a][b] = std::min(d[a][b], w);
  if (bwd) d[b][a] = std::min(d[b][a], w);
}

// C(A -> B) as (pairs, 1 - mean), mean over ordered evaluable pairs.
std::pair<int64_t, std::optional<double>> ref_one_sided(const CleanGraph& ga, const CleanGraph& gb, double snap_m,
                                                        bool directed, const MetricParams& params) {
  const double res = params.resolution_m;
  std::vector<Pm> a, b;
  for (const Point& p : ga.nodes) a.push_back({p.u * res, p.v * res});
  for (const Point& p : gb.nodes) b.push_back({p.u * res, p.v * res});
  const std::vector<Segment> sa = segments_of(ga), sb = segments_of(gb);
  Matrix da(a.size(), std::vector<double>(a.size(), kInf));
  for (size_t k = 0; k < a.size(); ++k) da[k][k] = 0.0;
  for (const Segment& s : sa) {
    const double w = std::hypot(a[s.j].x - a[s.i].x, a[s.j].y - a[s.i].y);
    add_arc(da, s.i, s.j, w, !directed || s.fwd, !directed || s.bwd);
  }
  floyd(da);
  // Snap, then split B's segments at the projections.
  std::vector<std::vector<std::pair<double, int32_t>>> on(sb.size());
  for (size_t n = 0; n < a.size(); ++n) {
    double best = kInf, best_t = 0.0;
    int32_t seg = -1;
    for (size_t k = 0; k < sb.size(); ++k) {
      double t = 0.0;
      const double d = seg_dist(a[n], b[sb[k].i], b[sb[k].j], &t);
      if (d < best) {
        best = d;
        best_t = t;
        seg = static_cast<int32_t>(k);
      }
    }
    if (seg >= 0 && best <= snap_m) on[seg].push_back({best_t, static_cast<int32_t>(n)});
  }
  std::vector<int32_t> node_of(a.size(), -1);
  std::vector<Pm> bpos = b;
  std::vector<std::tuple<size_t, size_t, bool, bool>> arcs;
  for (size_t k = 0; k < sb.size(); ++k) {
    std::sort(on[k].begin(), on[k].end());
    const Pm pa = b[sb[k].i], pb = b[sb[k].j];
    // Rule 3 (version 2): within 0.01 m of an end node along the segment is that node
    // (the nearer, i on a tie); within 0.01 m of the last new node shares it.
    const double len = std::hypot(pb.x - pa.x, pb.y - pa.y);
    std::vector<size_t> chain{static_cast<size_t>(sb[k].i)};
    double chain_at = 0.0;
    for (const auto& [t, n] : on[k]) {
      const double at = t * len, to_j = (1.0 - t) * len;
      if (at <= 0.01 && at <= to_j) {
        node_of[n] = sb[k].i;
      } else if (to_j <= 0.01) {
        node_of[n] = sb[k].j;
      } else {
        if (chain.size() == 1 || at - chain_at > 0.01) {
          chain.push_back(bpos.size());
          bpos.push_back({pa.x + t * (pb.x - pa.x), pa.y + t * (pb.y - pa.y)});
          chain_at = at;
        }
        node_of[n] = static_cast<int32_t>(chain.back());
      }
    }
    chain.push_back(sb[k].j);
    for (size_t c = 0; c + 1 < chain.size(); ++c)
      arcs.emplace_back(chain[c], chain[c + 1], !directed || sb[k].fwd, !directed || sb[k].bwd);
  }
  Matrix db(bpos.size(), std::vector<double>(bpos.size(), kInf));
  for (size_t k = 0; k < bpos.size(); ++k) db[k][k] = 0.0;
  for (const auto& [x, y, fwd, bwd] : arcs)
    add_arc(db, x, y, std::hypot(bpos[y].x - bpos[x].x, bpos[y].y - bpos[x].y), fwd, bwd);
  floyd(db);
  int64_t pairs = 0;
  double cost = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < a.size(); ++j) {
      const double la = da[i][j];
      if (i == j || la == kInf || la < params.min_path_m) continue;
      ++pairs;
      if (node_of[i] < 0 || node_of[j] < 0 || db[node_of[i]][node_of[j]] == kInf) {
        cost += 1.0;
        continue;
      }
      cost += std::min(1.0, std::abs(la - db[node_of[i]][node_of[j]]) / la);
    }
  }
  if (pairs == 0) return {0, std::nullopt};
  return {pairs, 1.0 - cost / static_cast<double>(pairs)};
}

void expect_same(const std::optional<double>& got, const std::optional<double>& want, const char* name, int trial) {
  ASSERT_EQ(got.has_value(), want.has_value()) << name << " trial " << trial;
  if (want) {
    EXPECT_NEAR(*got, *want, 1e-12) << name << " trial " << trial;
  }
}

TEST(AplsReference, FastPathMatchesAllPairsDefinition) {
  Rng rng(77);
  int partial = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const MetricParams params;
    const bool grid = trial % 2 == 0;
    const Graph gt = random_graph(rng, grid);
    const Graph pred =
        trial % 4 == 0 ? random_graph(rng, grid) : perturbed(rng, gt, rng.uniform(0.0, grid ? 2.0 : 12.0));
    const TileMeasurement t = measure("k", gt, &pred, params);
    const CleanGraph g = clean_graph(gt), p = clean_graph(pred);
    struct Variant {
      Metric first;
      double snap_m;
      bool directed;
    };
    for (const Variant& v : {Variant{kApls, params.snap_m, false}, Variant{kAplsDirected, params.snap_m, true},
                             Variant{kAplsStrict, params.strict_snap_m, false}}) {
      const auto [gt_pairs, c1] = ref_one_sided(g, p, v.snap_m, v.directed, params);
      const auto [pred_pairs, c2] = ref_one_sided(p, g, v.snap_m, v.directed, params);
      expect_same(t.values[v.first + 1], c1, metric_name(v.first + 1), trial);
      expect_same(t.values[v.first + 2], c2, metric_name(v.first + 2), trial);
      if (v.first == kApls) {
        EXPECT_EQ(t.counts[kAplsGtPairs], gt_pairs) << "trial " << trial;
        EXPECT_EQ(t.counts[kAplsPredPairs], pred_pairs) << "trial " << trial;
        if (c1 && *c1 > 0.0 && *c1 < 1.0) ++partial;
      }
    }
  }
  EXPECT_GT(partial, 30);  // most cases are neither perfect nor empty
}

// ---- Chamfer reference ----------------------------------------------------------------

// All-pairs nearest squared distance, summed over xs in order (the definition).
std::pair<double, double> ref_chamfer_one_way(const std::vector<Point>& xs, const std::vector<Point>& ys) {
  double sum2 = 0.0, sum1 = 0.0;
  for (const Point& x : xs) {
    double best = kInf;
    for (const Point& y : ys) {
      const double dx = x.u - y.u, dy = x.v - y.v;
      best = std::min(best, dx * dx + dy * dy);
    }
    sum2 += best;
    sum1 += std::sqrt(best);
  }
  return {sum2, sum1};
}

// Node sets (no edges needed: Chamfer uses every node): uniform, clustered, on an integer
// grid with many exact ties, with far outliers, and of very different sizes.
std::vector<Point> random_points(Rng& rng, int trial) {
  std::vector<Point> pts;
  const auto n = static_cast<int>(rng.uniform_int(int64_t{1}, int64_t{trial % 7 == 0 ? 3 : 300}));
  const double cu = rng.uniform(0, 256), cv = rng.uniform(0, 256);
  for (int k = 0; k < n; ++k) {
    Point p = trial % 3 == 0 ? Point{cu + rng.uniform(-5, 5), cv + rng.uniform(-5, 5)}
                             : Point{rng.uniform(-20, 276), rng.uniform(-20, 276)};
    if (trial % 2 == 0) p = {std::round(p.u / 4) * 4, std::round(p.v / 4) * 4};
    if (rng.bernoulli(0.02)) p = {rng.uniform(-5000, 5000), rng.uniform(-5000, 5000)};
    pts.push_back(p);
  }
  return pts;
}

TEST(ChamferReference, GridSearchEqualsAllPairsBitForBit) {
  Rng rng(4242);
  for (int trial = 0; trial < 300; ++trial) {
    Graph gt, pred;
    gt.nodes = random_points(rng, trial);
    pred.nodes = random_points(rng, trial / 2);
    const TileMeasurement t = measure("k", gt, &pred, MetricParams{});
    const auto [g2, g1] = ref_chamfer_one_way(gt.nodes, pred.nodes);
    const auto [p2, p1] = ref_chamfer_one_way(pred.nodes, gt.nodes);
    ASSERT_TRUE(t.values[kChamferPx2].has_value()) << "trial " << trial;
    EXPECT_EQ(*t.values[kChamferPx2], g2 + p2) << "trial " << trial;
    const double mean_m =
        0.5 * (g1 / static_cast<double>(gt.nodes.size()) + p1 / static_cast<double>(pred.nodes.size())) * 0.2;
    EXPECT_EQ(*t.values[kChamferMeanM], mean_m) << "trial " << trial;
  }
}

}  // namespace
}  // namespace nsg::metrics
