// GEO/TOPO sampling exactly as docs/metrics.md "GEO and TOPO" (rule numbers below refer to
// that section): the samples and sample graph of a cleaned graph (rules 2-3) and the GEO
// candidate pairs within the match radius in the order of rule 4. Built with
// -ffp-contract=off like the rest of the module: the sample positions and the quantized
// distances are plain IEEE double arithmetic.
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "geo_topo_samples.h"
#include "internal.h"

namespace nsg::metrics::detail {
namespace {

// Rule 2: k = max(1, ceil(L/step - 0.05)). Version 3 (was 1e-9): a segment a hair longer than
// a whole number of steps (every 2 m lane piece, moved by a rounding) keeps that number of
// pieces, so the sample counts do not jump under a move of a hundredth of a pixel.
constexpr double kCeilTol = 0.05;
constexpr double kQuantScale = 1e6;  // rule 4: q = floor(d2 * 1e6 + 0.5)

// Union-find over the node samples joined by chains; interior samples follow theirs.
void set_components(SampleGraph& sg) {
  std::vector<int32_t> parent(static_cast<size_t>(sg.n_node_samples));
  for (size_t n = 0; n < parent.size(); ++n) parent[n] = static_cast<int32_t>(n);
  auto root = [&](int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const Chain& c : sg.chains) parent[root(c.a)] = root(c.b);
  sg.comp.assign(sg.size(), -1);
  for (int32_t n = 0; n < sg.n_node_samples; ++n) sg.comp[n] = root(n);
  for (size_t x = static_cast<size_t>(sg.n_node_samples); x < sg.size(); ++x)
    sg.comp[x] = sg.comp[sg.chains[sg.chain_of_interior[x - sg.n_node_samples]].a];
}

}  // namespace

SampleGraph sample_graph(const CleanGraph& g, double step_px) {
  const std::vector<Segment> segs = segments_of(g);
  std::vector<int32_t> sample_of(g.nodes.size(), -1);
  for (const Segment& s : segs) sample_of[s.i] = sample_of[s.j] = 0;
  SampleGraph sg;
  for (size_t n = 0; n < g.nodes.size(); ++n) {
    if (sample_of[n] < 0) continue;
    sample_of[n] = static_cast<int32_t>(sg.pos.size());
    sg.pos.push_back(g.nodes[n]);
    sg.node_of.push_back(static_cast<int32_t>(n));
  }
  sg.n_node_samples = static_cast<int32_t>(sg.pos.size());
  sg.chains.reserve(segs.size());
  sg.chain_offset.assign(sg.pos.size() + 1, 0);
  const bool classed = !g.edge_flags.empty();
  if (classed) {
    sg.classes.assign(sg.pos.size(), 0);
    sg.flags.assign(sg.pos.size(), 0);
  }
  for (const Segment& s : segs) {
    const Point a = g.nodes[s.i], b = g.nodes[s.j];
    const double dx = b.u - a.u, dy = b.v - a.v;
    const double len = std::sqrt(dx * dx + dy * dy);
    const int k = std::max(1, static_cast<int>(std::ceil(len / step_px - kCeilTol)));
    const auto chain = static_cast<int32_t>(sg.chains.size());
    sg.chains.push_back(
        {sample_of[s.i], sample_of[s.j], static_cast<int32_t>(sg.pos.size()), k, len / k, s.fwd, s.bwd});
    ++sg.chain_offset[sample_of[s.i] + 1];
    ++sg.chain_offset[sample_of[s.j] + 1];
    if (classed) {
      sg.classes[sample_of[s.i]] |= s.classes;
      sg.classes[sample_of[s.j]] |= s.classes;
      sg.flags[sample_of[s.i]] |= s.flags;
      sg.flags[sample_of[s.j]] |= s.flags;
    }
    for (int s_idx = 1; s_idx < k; ++s_idx) {
      const double t = static_cast<double>(s_idx) / k;
      sg.pos.push_back({a.u + dx * t, a.v + dy * t});
      sg.chain_of_interior.push_back(chain);
      if (classed) {
        sg.classes.push_back(s.classes);
        sg.flags.push_back(s.flags);
      }
    }
  }
  for (int32_t n = 0; n < sg.n_node_samples; ++n) sg.chain_offset[n + 1] += sg.chain_offset[n];
  sg.chain_ids.resize(sg.chain_offset.back());
  std::vector<int32_t> fill(sg.chain_offset.begin(), sg.chain_offset.end() - 1);
  for (size_t c = 0; c < sg.chains.size(); ++c) {
    sg.chain_ids[fill[sg.chains[c].a]++] = static_cast<int32_t>(c);
    sg.chain_ids[fill[sg.chains[c].b]++] = static_cast<int32_t>(c);
  }
  set_components(sg);
  return sg;
}

namespace {

// Ascending sort of keys below 2^bits: LSD radix passes of 11 bits, the same order as
// std::sort (the keys are distinct integers) in linear time.
void radix_sort(std::vector<uint64_t>& keys, int bits) {
  constexpr int kDigitBits = 11;
  constexpr size_t kBuckets = size_t{1} << kDigitBits;
  std::vector<uint64_t> tmp(keys.size());
  std::vector<uint32_t> count(kBuckets);
  for (int shift = 0; shift < bits; shift += kDigitBits) {
    std::fill(count.begin(), count.end(), 0);
    for (uint64_t k : keys) ++count[(k >> shift) & (kBuckets - 1)];
    // A digit shared by every key leaves the order as it is.
    if (keys.empty() || count[(keys[0] >> shift) & (kBuckets - 1)] == keys.size()) continue;
    uint32_t sum = 0;
    for (uint32_t& c : count) {
      const uint32_t n = c;
      c = sum;
      sum += n;
    }
    for (uint64_t k : keys) tmp[count[(k >> shift) & (kBuckets - 1)]++] = k;
    keys.swap(tmp);
  }
}

// Sorts by (q, g, p). When the three fit in 64 bits (always for tiles of sane size) the
// packed keys sort much faster than the three-way comparison; the order is the same.
void sort_candidates(std::vector<Candidate>& cands, int64_t q_max, size_t n_g, size_t n_p) {
  const int bits_q = std::bit_width(static_cast<uint64_t>(q_max));
  const int bits_g = std::bit_width(n_g), bits_p = std::bit_width(n_p);
  if (bits_q + bits_g + bits_p > 64) {
    std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
      if (a.q != b.q) return a.q < b.q;
      if (a.g != b.g) return a.g < b.g;
      return a.p < b.p;
    });
    return;
  }
  std::vector<uint64_t> keys(cands.size());
  for (size_t k = 0; k < cands.size(); ++k) {
    keys[k] = (static_cast<uint64_t>(cands[k].q) << (bits_g + bits_p)) | (static_cast<uint64_t>(cands[k].g) << bits_p) |
              static_cast<uint64_t>(cands[k].p);
  }
  radix_sort(keys, bits_q + bits_g + bits_p);
  const uint64_t mask_g = (uint64_t{1} << bits_g) - 1, mask_p = (uint64_t{1} << bits_p) - 1;
  for (size_t k = 0; k < keys.size(); ++k) {
    cands[k] = {static_cast<int64_t>(keys[k] >> (bits_g + bits_p)), static_cast<int32_t>((keys[k] >> bits_p) & mask_g),
                static_cast<int32_t>(keys[k] & mask_p)};
  }
}

}  // namespace

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
  auto cell_of = [&](double x, double origin) { return static_cast<int64_t>(std::floor((x - origin) / cell)); };
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
  sort_candidates(out, q_max, gt.size(), pred.size());
  return out;
}

}  // namespace nsg::metrics::detail
