// The crossing rule (skeleton.h, split_crossings): in a lane graph, lanes that cross share
// no node, but a thinned mask joins them wherever they touch. A junction whose branches
// pair into straight-through lines is taken apart into those lines. Decisions are made on
// the graph as traced, then the branches are stitched through the junctions taken apart.
#include <algorithm>
#include <cmath>

#include "nsg/skeleton/skeleton.h"

namespace nsg::skeleton {
namespace {

// Near a junction, thinning bends each branch toward the junction's centre over about half
// a lane mask's width; a branch's leaving direction is taken between these arc lengths,
// past the bend and before a curving lane turns away.
constexpr double kProbeNearPx = 3.0;
constexpr double kProbeFarPx = 12.0;
// Four lines through one point at most: 8 ends, 105 pairings to try.
constexpr size_t kMaxCrossingEnds = 8;
// Two junctions are one crossing when each line through them passes this close to the
// middle of the stretch they share (a lane's half-width at 0.2 m/px is about 9 px; an X
// drawn from two straight lines passes within a pixel).
constexpr double kMaxThroughOffsetPx = 3.0;
// At an X of lines crossing at θ ≤ 90 deg thinned into two junctions, each junction's outer
// branches leave at about 180 - θ/2 ≥ 135 deg from the branch the junctions share; at an H
// (two lanes and a connector between them) one leaves at 90 deg or less. (Measured on the
// demo's test tiles: 95 keeps the H's apart; 120 also refuses crossings whose shared
// branch runs along one of the lanes.)
constexpr double kMinOuterAngleDeg = 95.0;

// One end of a branch: its first (a) or its second (b).
struct BranchEnd {
  int branch = -1;
  bool at_b = false;
};
int end_id(const BranchEnd& e) { return 2 * e.branch + (e.at_b ? 1 : 0); }
BranchEnd end_of_id(int id) { return {id / 2, id % 2 == 1}; }
BranchEnd other_end(const BranchEnd& e) { return {e.branch, !e.at_b}; }

int vertex_at(const SkeletonGraph& g, const BranchEnd& e) {
  const SkeletonGraph::Branch& b = g.branches[static_cast<size_t>(e.branch)];
  return e.at_b ? b.b : b.a;
}

// The branch's polyline starting at `e`.
std::vector<cv::Point2d> points_from(const SkeletonGraph& g, const BranchEnd& e) {
  std::vector<cv::Point2d> pts = g.branches[static_cast<size_t>(e.branch)].points;
  if (e.at_b) std::reverse(pts.begin(), pts.end());
  return pts;
}

double length_px(const std::vector<cv::Point2d>& pts) {
  double len = 0.0;
  for (size_t k = 1; k < pts.size(); ++k) len += cv::norm(pts[k] - pts[k - 1]);
  return len;
}

// The point at arc length s_px along pts (the last point beyond the end).
cv::Point2d point_at(const std::vector<cv::Point2d>& pts, double s_px) {
  for (size_t k = 1; k < pts.size(); ++k) {
    const double step = cv::norm(pts[k] - pts[k - 1]);
    if (s_px <= step && step > 0.0) return pts[k - 1] + (pts[k] - pts[k - 1]) * (s_px / step);
    s_px -= step;
  }
  return pts.back();
}

// The unit direction in which a branch leaves its end `e` (zero for a branch of no length).
cv::Point2d leaving_direction(const SkeletonGraph& g, const BranchEnd& e) {
  const std::vector<cv::Point2d> pts = points_from(g, e);
  const double len = length_px(pts);
  const cv::Point2d d = point_at(pts, std::min(kProbeFarPx, len)) - point_at(pts, std::min(kProbeNearPx, len / 4));
  const double norm = cv::norm(d);
  return norm > 0.0 ? d / norm : d;
}

// How far two leaving directions are from opposite: 0 deg for a straight line.
double bend_deg(const cv::Point2d& d1, const cv::Point2d& d2) {
  const double cos_opposite = std::clamp(-d1.dot(d2), -1.0, 1.0);
  return std::acos(cos_opposite) * 180.0 / M_PI;
}

// The pairing of all `dirs` into straight lines with the least total bend, every pair's bend
// ≤ tolerance_deg; empty when there is none. Exhaustive: at most kMaxCrossingEnds ends.
struct Pairing {
  std::vector<std::array<int, 2>> pairs;
  double total_bend_deg = 0.0;
};
void best_pairing(const std::vector<cv::Point2d>& dirs, double tolerance_deg, std::vector<char>& used, Pairing& current,
                  Pairing& best) {
  const auto first = std::find(used.begin(), used.end(), 0);
  if (first == used.end()) {
    if (best.pairs.empty() || current.total_bend_deg < best.total_bend_deg) best = current;
    return;
  }
  const int i = static_cast<int>(first - used.begin());
  used[static_cast<size_t>(i)] = 1;
  for (int j = i + 1; j < static_cast<int>(dirs.size()); ++j) {
    const double bend = bend_deg(dirs[static_cast<size_t>(i)], dirs[static_cast<size_t>(j)]);
    if (used[static_cast<size_t>(j)] || bend > tolerance_deg) continue;
    used[static_cast<size_t>(j)] = 1;
    current.pairs.push_back({i, j});
    current.total_bend_deg += bend;
    best_pairing(dirs, tolerance_deg, used, current, best);
    current.total_bend_deg -= bend;
    current.pairs.pop_back();
    used[static_cast<size_t>(j)] = 0;
  }
  used[static_cast<size_t>(i)] = 0;
}

// Which branch end continues straight through a crossing into which (-1: none), and the
// branches that vanish with the crossings taken apart.
struct Crossings {
  std::vector<int> link;   // per end_id
  std::vector<char> drop;  // per branch
};

// The skeleton's junctions as the rule reads them: the branch ends at each vertex, and
// which vertices a crossing has already taken.
struct Junctions {
  const SkeletonGraph& g;
  std::vector<std::vector<BranchEnd>> ends_of_vertex;
  std::vector<char> taken;

  explicit Junctions(const SkeletonGraph& graph)
      : g(graph), ends_of_vertex(graph.vertices.size()), taken(graph.vertices.size(), 0) {
    for (size_t k = 0; k < g.branches.size(); ++k) {
      ends_of_vertex[static_cast<size_t>(g.branches[k].a)].push_back({static_cast<int>(k), false});
      ends_of_vertex[static_cast<size_t>(g.branches[k].b)].push_back({static_cast<int>(k), true});
    }
  }
  size_t degree(int v) const { return ends_of_vertex[static_cast<size_t>(v)].size(); }
  // The ends at v except those of branch `skip`.
  std::vector<BranchEnd> ends_at(int v, int skip = -1) const {
    std::vector<BranchEnd> out;
    for (const BranchEnd& e : ends_of_vertex[static_cast<size_t>(v)])
      if (e.branch != skip) out.push_back(e);
    return out;
  }
};

// Whether a branch leaves these ends twice (a loop: no straight line to make of it).
bool has_loop(const std::vector<BranchEnd>& ends) {
  std::vector<int> branches;
  for (const BranchEnd& e : ends) branches.push_back(e.branch);
  std::sort(branches.begin(), branches.end());
  return std::adjacent_find(branches.begin(), branches.end()) != branches.end();
}

void link_pairs(Crossings& x, const std::vector<BranchEnd>& ends, const std::vector<std::array<int, 2>>& pairs) {
  for (const auto& [i, j] : pairs) {
    x.link[static_cast<size_t>(end_id(ends[static_cast<size_t>(i)]))] = end_id(ends[static_cast<size_t>(j)]);
    x.link[static_cast<size_t>(end_id(ends[static_cast<size_t>(j)]))] = end_id(ends[static_cast<size_t>(i)]);
  }
}

// A junction of 4 to kMaxCrossingEnds branches (an even number) that all pair into
// straight lines: taken apart.
void split_junction(Junctions& j, int v, const CrossingRule& rule, Crossings& x) {
  const std::vector<BranchEnd> ends = j.ends_at(v);
  if (ends.size() < 4 || ends.size() % 2 != 0 || ends.size() > kMaxCrossingEnds || has_loop(ends)) return;
  std::vector<cv::Point2d> dirs;
  for (const BranchEnd& e : ends) dirs.push_back(leaving_direction(j.g, e));
  std::vector<char> used(dirs.size(), 0);
  Pairing current, best;
  best_pairing(dirs, rule.tolerance_deg, used, current, best);
  if (best.pairs.empty()) return;  // a T, a split or a merge: the junction stays
  link_pairs(x, ends, best.pairs);
  j.taken[static_cast<size_t>(v)] = 1;
}

// How far `m` lies from the line through p and q, px.
double offset_px(const cv::Point2d& m, const cv::Point2d& p, const cv::Point2d& q) {
  const cv::Point2d d = q - p;
  const double len = cv::norm(d);
  return len > 0.0 ? std::abs(d.cross(m - p)) / len : cv::norm(m - p);
}

// Where a branch's leaving direction is measured to (its line's point past the bend).
cv::Point2d probe_point(const SkeletonGraph& g, const BranchEnd& e) {
  const std::vector<cv::Point2d> pts = points_from(g, e);
  return point_at(pts, std::min(kProbeFarPx, length_px(pts)));
}

// Whether both outer branches at a junction of a pair leave it facing away from the branch
// the two junctions share (at least kMinOuterAngleDeg from it), as at an X thinned into two
// junctions. At an H (two lanes and a short connector between them) a lane leaves at 90 deg
// or less from the connector.
bool opens_away(const SkeletonGraph& g, const std::vector<BranchEnd>& outer, const BranchEnd& shared) {
  const cv::Point2d d_shared = leaving_direction(g, shared);
  for (const BranchEnd& e : outer)
    if (180.0 - bend_deg(leaving_direction(g, e), d_shared) < kMinOuterAngleDeg) return false;
  return true;
}

// Two 3-way junctions joined by a short branch `k`, as thinning leaves an X whose lines
// cross at a shallow angle (the shared stretch grows as the angle closes): taken apart
// when each end at one junction continues straight into an end at the other, through the
// middle of the shared stretch (so a merge followed by a split, or a lane change between
// two lanes, stays).
void split_junction_pair(Junctions& j, int k, const CrossingRule& rule, Crossings& x) {
  const SkeletonGraph::Branch& shared = j.g.branches[static_cast<size_t>(k)];
  const std::vector<BranchEnd> at_a = j.ends_at(shared.a, k), at_b = j.ends_at(shared.b, k);
  std::vector<BranchEnd> ends = at_a;
  ends.insert(ends.end(), at_b.begin(), at_b.end());
  if (at_a.size() != 2 || at_b.size() != 2 || has_loop(ends)) return;
  if (!opens_away(j.g, at_a, {k, false}) || !opens_away(j.g, at_b, {k, true})) return;
  const cv::Point2d middle = point_at(shared.points, length_px(shared.points) / 2);
  Pairing best;
  for (const Pairing& p : {Pairing{{{0, 2}, {1, 3}}, 0.0}, Pairing{{{0, 3}, {1, 2}}, 0.0}}) {
    Pairing scored = p;
    bool straight = true;
    for (const auto& [a, b] : p.pairs) {
      const BranchEnd& ea = ends[static_cast<size_t>(a)];
      const BranchEnd& eb = ends[static_cast<size_t>(b)];
      const double bend = bend_deg(leaving_direction(j.g, ea), leaving_direction(j.g, eb));
      straight = straight && bend <= rule.tolerance_deg &&
                 offset_px(middle, probe_point(j.g, ea), probe_point(j.g, eb)) <= kMaxThroughOffsetPx;
      scored.total_bend_deg += bend;
    }
    if (straight && (best.pairs.empty() || scored.total_bend_deg < best.total_bend_deg)) best = scored;
  }
  if (best.pairs.empty()) return;
  link_pairs(x, ends, best.pairs);
  x.drop[static_cast<size_t>(k)] = 1;
  j.taken[static_cast<size_t>(shared.a)] = j.taken[static_cast<size_t>(shared.b)] = 1;
}

// The crossings of the graph as traced: single junctions first, then pairs of 3-way
// junctions joined by a branch shorter than rule.merge_px, the shortest first; a junction
// takes part in one crossing at most.
Crossings find_crossings(const SkeletonGraph& g, const CrossingRule& rule) {
  Junctions j(g);
  Crossings x{std::vector<int>(2 * g.branches.size(), -1), std::vector<char>(g.branches.size(), 0)};
  for (int v = 0; v < static_cast<int>(g.vertices.size()); ++v) split_junction(j, v, rule, x);
  std::vector<std::pair<double, int>> shared_by_length;
  for (int k = 0; k < static_cast<int>(g.branches.size()); ++k) {
    const SkeletonGraph::Branch& b = g.branches[static_cast<size_t>(k)];
    const double len = length_px(b.points);
    if (b.a != b.b && j.degree(b.a) == 3 && j.degree(b.b) == 3 && len < rule.merge_px)
      shared_by_length.push_back({len, k});
  }
  std::sort(shared_by_length.begin(), shared_by_length.end());
  for (const auto& [len, k] : shared_by_length) {
    const SkeletonGraph::Branch& b = g.branches[static_cast<size_t>(k)];
    if (!j.taken[static_cast<size_t>(b.a)] && !j.taken[static_cast<size_t>(b.b)]) split_junction_pair(j, k, rule, x);
  }
  return x;
}

// Appends `pts` to `line`, leaving out a first point equal to the line's last.
void append(std::vector<cv::Point2d>& line, const std::vector<cv::Point2d>& pts) {
  const bool joined = !line.empty() && !pts.empty() && line.back() == pts.front();
  line.insert(line.end(), pts.begin() + (joined ? 1 : 0), pts.end());
}

// The polyline without its first head_px and last tail_px of length (the cuts interpolated).
std::vector<cv::Point2d> trimmed(const std::vector<cv::Point2d>& pts, double head_px, double tail_px) {
  const double len = length_px(pts);
  std::vector<cv::Point2d> out{point_at(pts, head_px)};
  double s = 0.0;
  for (size_t k = 1; k + 1 < pts.size(); ++k) {
    s += cv::norm(pts[k] - pts[k - 1]);
    if (s > head_px && s < len - tail_px) out.push_back(pts[k]);
  }
  out.push_back(point_at(pts, len - tail_px));
  return out;
}

// A branch's points from `at`, the stretch near each end that a crossing links cut off:
// there thinning bends the branch toward the junction (for an X at a shallow angle, along
// the stretch both lines share), so the lines through a crossing join their branches
// where they run true, with a straight piece.
std::vector<cv::Point2d> piece_from(const SkeletonGraph& g, const Crossings& x, const BranchEnd& at) {
  std::vector<cv::Point2d> pts = points_from(g, at);
  const double cut_px = std::min(kProbeFarPx, length_px(pts) / 3);
  const bool linked_at = x.link[static_cast<size_t>(end_id(at))] >= 0;
  const bool linked_far = x.link[static_cast<size_t>(end_id(other_end(at)))] >= 0;
  if (!linked_at && !linked_far) return pts;
  return trimmed(pts, linked_at ? cut_px : 0.0, linked_far ? cut_px : 0.0);
}

// One stitched branch: from `start` along its branch and on through every crossing link,
// to an end without one (or, around a closed line of crossings, back to `start`).
SkeletonGraph::Branch stitch_from(SkeletonGraph& g, const Crossings& x, BranchEnd start, std::vector<char>& visited) {
  SkeletonGraph::Branch out;
  out.a = vertex_at(g, start);
  BranchEnd at = start;
  while (true) {
    visited[static_cast<size_t>(at.branch)] = 1;
    append(out.points, piece_from(g, x, at));
    const BranchEnd far = other_end(at);
    const int next = x.link[static_cast<size_t>(end_id(far))];
    if (next < 0) {
      out.b = vertex_at(g, far);
      return out;
    }
    if (next == end_id(start)) {  // closed: a new vertex where the line was started
      out.a = out.b = static_cast<int>(g.vertices.size());
      g.vertices.push_back(out.points.front());
      append(out.points, {out.points.front()});
      return out;
    }
    at = end_of_id(next);
  }
}

}  // namespace

void split_crossings(SkeletonGraph& graph, const CrossingRule& rule) {
  const Crossings x = find_crossings(graph, rule);
  if (std::all_of(x.link.begin(), x.link.end(), [](int l) { return l < 0; })) return;
  std::vector<char> visited(graph.branches.size(), 0);
  std::vector<SkeletonGraph::Branch> out;
  // Branches in their order, each line started from an end outside any crossing (the
  // branches no crossing touches keep their place and direction); closed lines last.
  for (const bool closed : {false, true}) {
    for (int k = 0; k < static_cast<int>(graph.branches.size()); ++k) {
      if (visited[static_cast<size_t>(k)] || x.drop[static_cast<size_t>(k)]) continue;
      for (const BranchEnd start : {BranchEnd{k, false}, BranchEnd{k, true}}) {
        if (!closed && x.link[static_cast<size_t>(end_id(start))] >= 0) continue;
        out.push_back(stitch_from(graph, x, start, visited));
        break;
      }
    }
  }
  graph.branches = std::move(out);
  drop_unused_vertices(graph);
}

}  // namespace nsg::skeleton
