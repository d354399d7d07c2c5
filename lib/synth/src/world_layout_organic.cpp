// The organic layout of the world builder (world_builder.h, city.layout = "organic"): one
// hand-drawn city plan scaled to the grid's rectangle (origin_m, blocks · block_size_m)
// with every feature the grid lacks — curved arterials with clothoid-like bends, skewed
// junctions, T and Y junctions, a one-way roundabout, a lane drop with an added lane, a
// turn pocket, a divided boulevard with a median and a ramp leaving and rejoining it.
// With city.local_streets, five local streets fill the plan's empty quarters, splitting
// the plan's roads where they meet them (ten more junctions; the demo world has them).
// Lane counts, parking, bend radii and parks come from the builder's Rng. The plan is
// nodes plus roads (control polylines or ring arcs); `realize` turns it into the nodes and
// pieces the later, layout-agnostic stages read.
#include <algorithm>
#include <cmath>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "road_geometry.h"
#include "world_builder.h"
#include "world_organic.h"

namespace nsg::synth::world_detail {

namespace {

// The plan's nodes.
enum Node : int {
  kRingN,      // the roundabout's entries and exits (north, east, south)
  kRingE,      //
  kRingS,      //
  kN1,         // T junction on the arterial (S1 leaves south)
  kLaneDrop,   // transition: the arterial narrows eastbound, widens westbound
  kN2,         // Y junction: the arterial climbs off, the diagonal leaves
  kN3,         // T junction on the arterial (S2 leaves south)
  kE1,         // skewed T junction: the diagonal meets the arterial's east side
  kSE,         // T junction: the arterial meets the boulevard's east end
  kK,          // T junction: the roundabout's east road meets S1
  kBT,         // transition: the two-way road splits into the boulevard's carriageways
  kB1,         // S1 meets the boulevard
  kDiverge,    // transition: the ramp leaves the eastbound carriageway
  kMerge,      // transition: the ramp rejoins it
  kB2,         // S2 meets the boulevard
  kX,          // skewed 4-way crossing of S2 and the diagonal
  kPocket,     // transition: the turn pocket opens on S2 before X
  kNodeCount,  //
};

// The local streets' nodes (city.local_streets), after the plan's own so a city without
// them keeps its node numbers.
enum LocalNode : int {
  kP = kNodeCount,  // T junction: the local street north of K leaves S1
  kD,               // skewed 4-way crossing of that street and the diagonal
  kT2,              // T junction: it meets S2 north of the turn pocket
  kQ,               // T junction: the mid street from K meets S2 south of X
  kM3,              // T junction: S3 leaves the mid street south
  kB3,              // S3 meets the boulevard (both carriageways pass through)
  kR,               // skewed T junction: the street from Q meets the arterial's last stretch
  kW0,              // T junction: the west street leaves the arterial
  kW1,              // 4-way crossing: the west street crosses the roundabout's east road
  kW2,              // T junction: the west street meets the boulevard's approach
  kAllNodeCount,    //
};

constexpr double kMedianM = 4.0;                  // between the boulevard's carriageways
constexpr double kRampShiftM = 14.0;              // how far the ramp runs beside the boulevard
constexpr double kClimbRad = 25.0 * kPi / 180.0;  // the arterial's Y branch

struct PlanNode {
  Eigen::Vector2d centre{0.0, 0.0};
  NodeKind kind = NodeKind::kJunction;
  double gap_m = 0.0;  // transitions: half the gap the connectors bridge
};

struct RoadPlan {
  int street = 0;
  int a = -1, b = -1;
  std::vector<Eigen::Vector2d> poly;  // the axis, first and last point on the node arms
  double bend_radius_m = 60.0;
  bool spiral = true;  // clothoid-like bends, else single arcs
  bool ring = false;   // an arc of the roundabout between the nodes' angles
  double angle_a = 0.0, angle_b = 0.0;
};

Eigen::Vector2d left_of(const Eigen::Vector2d& u) { return {-u.y(), u.x()}; }

}  // namespace

class OrganicPlanner {
 public:
  OrganicPlanner(const CityConfig& city, bool rht, Rng& rng) : city_(city), rht_(rht), rng_(rng) {}

  void plan();
  void realize(std::vector<Street>& streets, std::vector<Intersection>& nodes, std::vector<Piece>& pieces);
  void choose_parks(const std::vector<Piece>& pieces, const std::vector<Street>& streets,
                    std::vector<std::pair<Eigen::Vector2d, double>>& parks);

 private:
  Eigen::Vector2d at(double u, double v) const { return {x0_ + u * w_, y0_ + v * h_}; }
  int street(int n_fwd, int n_bwd, bool parking, bool pocket = false);
  int random_street(bool allow_parking);
  void road(int street, int a, int b, std::vector<Eigen::Vector2d> poly);
  void plan_nodes();
  void plan_arterial();
  void plan_boulevard();
  void plan_cross_streets();
  void plan_roundabout();
  void plan_local_streets();
  void split_road(int a, int b, int node);
  std::vector<Arm> arms_of(int node) const;
  Arm arm(const RoadPlan& r, bool at_a) const;

  const CityConfig& city_;
  bool rht_;
  Rng& rng_;
  double x0_ = 0, y0_ = 0, w_ = 0, h_ = 0;
  double ring_radius_m_ = 25.0;
  Eigen::Vector2d ring_centre_{0.0, 0.0};
  std::vector<PlanNode> nodes_;
  std::vector<RoadPlan> roads_;
  std::vector<Street> streets_;
};

int OrganicPlanner::street(int n_fwd, int n_bwd, bool parking, bool pocket) {
  Street s;
  s.lane_w = city_.lane_width_m;
  s.n_fwd = n_fwd;
  s.n_bwd = n_bwd;
  s.parking = parking;
  s.pocket = pocket;
  streets_.push_back(s);
  return static_cast<int>(streets_.size()) - 1;
}

int OrganicPlanner::random_street(bool allow_parking) {
  const int max_lanes = city_.max_lanes_per_direction;
  const int n_fwd = static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{max_lanes}));
  const int n_bwd = static_cast<int>(rng_.uniform_int(int64_t{1}, int64_t{max_lanes}));
  const bool parking = allow_parking && rng_.bernoulli(city_.parking_fraction);
  return street(n_fwd, n_bwd, parking);
}

void OrganicPlanner::road(int street, int a, int b, std::vector<Eigen::Vector2d> poly) {
  RoadPlan r;
  r.street = street;
  r.a = a;
  r.b = b;
  r.poly = std::move(poly);
  r.bend_radius_m = rng_.uniform(45.0, 80.0);
  roads_.push_back(std::move(r));
}

void OrganicPlanner::plan() {
  x0_ = city_.origin_m[0];
  y0_ = city_.origin_m[1];
  w_ = city_.blocks_x * city_.block_size_m;
  h_ = city_.blocks_y * city_.block_size_m;
  ring_radius_m_ = std::clamp(0.07 * std::min(w_, h_), 22.0, 30.0);
  plan_nodes();
  plan_roundabout();
  plan_arterial();
  plan_boulevard();
  plan_cross_streets();
  if (city_.local_streets) plan_local_streets();
}

// Columns and rows as fractions of the rectangle; the diagonal from the Y junction N2 to
// E1 crosses the column of S2 at X, skewed by 90° minus its slope.
void OrganicPlanner::plan_nodes() {
  nodes_.assign(kNodeCount, PlanNode{});
  ring_centre_ = at(0.10, 0.50);
  const double rr = ring_radius_m_;
  nodes_[kRingN].centre = ring_centre_ + Eigen::Vector2d(0.0, rr);
  nodes_[kRingE].centre = ring_centre_ + Eigen::Vector2d(rr, 0.0);
  nodes_[kRingS].centre = ring_centre_ + Eigen::Vector2d(0.0, -rr);
  nodes_[kN1].centre = at(0.36, 0.84);
  nodes_[kLaneDrop] = {at(0.46, 0.84), NodeKind::kTransition, 12.0};
  nodes_[kN2].centre = at(0.56, 0.84);
  nodes_[kN3].centre = at(0.80, 0.91);
  nodes_[kE1].centre = at(0.97, 0.36);
  nodes_[kSE].centre = at(0.97, 0.14);
  nodes_[kK].centre = at(0.36, 0.50);
  nodes_[kBT] = {at(0.26, 0.14), NodeKind::kTransition, 12.0};
  nodes_[kB1].centre = at(0.36, 0.14);
  nodes_[kDiverge] = {at(0.44, 0.14), NodeKind::kTransition, 10.0};
  nodes_[kMerge] = {at(0.72, 0.14), NodeKind::kTransition, 10.0};
  nodes_[kB2].centre = at(0.80, 0.14);
  const Eigen::Vector2d n2 = nodes_[kN2].centre, e1 = nodes_[kE1].centre;
  const double f = (at(0.80, 0.0).x() - n2.x()) / (e1.x() - n2.x());
  nodes_[kX].centre = n2 + f * (e1 - n2);
  const Eigen::Vector2d down = (nodes_[kX].centre - nodes_[kN3].centre).normalized();
  nodes_[kPocket] = {nodes_[kX].centre - down * 45.0, NodeKind::kTransition, 8.0};
}

// The ring runs counter-clockwise where traffic keeps right (entries and exits are right
// turns), clockwise where it keeps left.
void OrganicPlanner::plan_roundabout() {
  const int ring = street(1, 0, false);
  const double angle[] = {kPi / 2.0, 0.0, 3.0 * kPi / 2.0};  // kRingN, kRingE, kRingS
  const int order_ccw[] = {kRingE, kRingN, kRingS};
  for (int k = 0; k < 3; ++k) {
    int a = order_ccw[k], b = order_ccw[(k + 1) % 3];
    if (!rht_) std::swap(a, b);
    RoadPlan r;
    r.street = ring;
    r.a = a;
    r.b = b;
    r.ring = true;
    r.angle_a = angle[a - kRingN];
    r.angle_b = angle[b - kRingN];
    roads_.push_back(r);
  }
}

// The arterial: from the roundabout north, a clothoid-like bend east, T junction N1, the
// lane drop, the Y junction N2 where it climbs off at 25°, T junction N3, a bend south to
// the skewed T junction E1 and down to the boulevard.
void OrganicPlanner::plan_arterial() {
  const Eigen::Vector2d rn = nodes_[kRingN].centre, n1 = nodes_[kN1].centre, n2 = nodes_[kN2].centre;
  const Eigen::Vector2d n3 = nodes_[kN3].centre, e1 = nodes_[kE1].centre;
  road(street(1, 1, false), kRingN, kN1, {rn, {rn.x(), n1.y()}, n1});
  road(street(2, 2, rng_.bernoulli(city_.parking_fraction)), kN1, kLaneDrop, {n1, nodes_[kLaneDrop].centre});
  road(street(1, 1, rng_.bernoulli(city_.parking_fraction)), kLaneDrop, kN2, {nodes_[kLaneDrop].centre, n2});
  const double climb = n3.y() - n2.y();
  const Eigen::Vector2d v4 =
      n2 + climb / std::sin(kClimbRad) * Eigen::Vector2d(std::cos(kClimbRad), std::sin(kClimbRad));
  road(random_street(true), kN2, kN3, {n2, v4, n3});
  road(random_street(false), kN3, kE1, {n3, {e1.x(), n3.y()}, e1});
  road(random_street(true), kE1, kSE, {e1, nodes_[kSE].centre});
}

// The boulevard: a two-way road from the roundabout bends east and splits at BT into two
// one-way carriageways kMedianM apart; the ramp leaves the eastbound one at the diverge
// node on its curb side, runs kRampShiftM beside it and merges back.
void OrganicPlanner::plan_boulevard() {
  const double w = city_.lane_width_m, curb = rht_ ? -1.0 : 1.0;
  const Eigen::Vector2d rs = nodes_[kRingS].centre, bt = nodes_[kBT].centre;
  road(street(1, 1, false), kRingS, kBT, {rs, {rs.x(), bt.y()}, bt});
  const int eb = street(2, 0, false), wb = street(2, 0, false);
  const double off = curb * (kMedianM / 2.0 + w);  // each carriageway's axis, in its own frame
  auto carriageway = [&](int st, int a, int b) {
    const Eigen::Vector2d ca = nodes_[a].centre, cb = nodes_[b].centre;
    const Eigen::Vector2d n = left_of((cb - ca).normalized()) * off;
    road(st, a, b, {ca + n, cb + n});
  };
  const int east[] = {kBT, kB1, kDiverge, kMerge, kB2, kSE};
  for (int k = 0; k + 1 < 6; ++k) carriageway(eb, east[k], east[k + 1]);
  const int west[] = {kSE, kB2, kB1, kBT};
  for (int k = 0; k + 1 < 4; ++k) carriageway(wb, west[k], west[k + 1]);
  // The ramp: beside the carriageway's curb lane, out by kRampShiftM and back.
  const Eigen::Vector2d d = nodes_[kDiverge].centre, m = nodes_[kMerge].centre;
  const Eigen::Vector2d u = (m - d).normalized(), n = left_of(u);
  const double near = curb * (kMedianM / 2.0 + 2.0 * w + w / 2.0), far = near + curb * kRampShiftM;
  // Straight beside the carriageway for `leg` (its gap and a bend), out over `run`, and at
  // least 24 m straight between the two bends in the middle.
  const double leg = nodes_[kDiverge].gap_m + 11.0;
  const double run = std::clamp(((m - d).norm() - 2.0 * leg - 24.0) / 2.0, 15.0, 30.0);
  road(street(1, 0, false), kDiverge, kMerge,
       {d + n * near, d + u * leg + n * near, d + u * (leg + run) + n * far, m - u * (leg + run) + n * far,
        m - u * leg + n * near, m + n * near});
  roads_.back().spiral = false;  // short bends: single arcs
  roads_.back().bend_radius_m = 40.0;
}

// Streets across the city: S1 (N1–K–B1, T junctions), the roundabout's east road to K, the
// diagonal N2–X–E1 and S2 (N3–pocket–X–B2) with the turn pocket before X.
void OrganicPlanner::plan_cross_streets() {
  auto straight = [&](int st, int a, int b) { road(st, a, b, {nodes_[a].centre, nodes_[b].centre}); };
  straight(random_street(true), kN1, kK);
  straight(random_street(true), kK, kB1);
  straight(street(1, 1, false), kRingE, kK);
  straight(random_street(true), kN2, kX);
  straight(random_street(true), kX, kE1);
  const int s2 = random_street(false);
  straight(s2, kN3, kPocket);
  const Street before = streets_[static_cast<size_t>(s2)];
  straight(street(before.n_fwd + 1, before.n_bwd, false, true), kPocket, kX);
  straight(random_street(true), kX, kB2);
}

// Local streets (city.local_streets) in the plan's empty quarters, each ending on a road
// of the plan, which is split there: a street from S1 over the diagonal to S2, the mid
// street from K to S2 with S3 down to the boulevard, a street from S2 to the arterial's
// last stretch, and the west street from the arterial over the roundabout's east road to
// the boulevard's approach. Places are fractions of the rectangle like the plan's nodes.
void OrganicPlanner::plan_local_streets() {
  nodes_.resize(kAllNodeCount);
  auto place = [&](int node, Eigen::Vector2d centre, int a, int b) {
    nodes_[static_cast<size_t>(node)].centre = centre;
    split_road(a, b, node);
  };
  place(kP, at(0.36, 0.65), kN1, kK);
  place(kT2, at(0.80, 0.80), kN3, kPocket);
  // D: where P–T2 crosses the diagonal N2–X (p + s·(t − p) = n2 + r·(x − n2), solved for s).
  const Eigen::Vector2d p = nodes_[kP].centre, t = nodes_[kT2].centre;
  const Eigen::Vector2d n2 = nodes_[kN2].centre, x = nodes_[kX].centre;
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
  place(kD, p + cross(n2 - p, n2 - x) / cross(t - p, n2 - x) * (t - p), kN2, kX);
  place(kQ, at(0.80, 0.38), kX, kB2);
  const Eigen::Vector2d k = nodes_[kK].centre, q = nodes_[kQ].centre;
  nodes_[kM3].centre = k + (at(0.58, 0.0).x() - k.x()) / (q.x() - k.x()) * (q - k);
  nodes_[kB3].centre = at(0.58, 0.14);
  split_road(kDiverge, kMerge, kB3);  // the eastbound carriageway (the ramp is farther)
  split_road(kB2, kB1, kB3);          // the westbound one
  place(kR, at(0.97, 0.25), kE1, kSE);
  place(kW0, at(0.23, 0.84), kRingN, kN1);
  place(kW1, at(0.23, 0.50), kRingE, kK);
  place(kW2, at(0.20, 0.14), kRingS, kBT);

  auto straight = [&](int st, int a, int b) { road(st, a, b, {nodes_[a].centre, nodes_[b].centre}); };
  const int north = random_street(true);
  straight(north, kP, kD);
  straight(north, kD, kT2);
  const int mid = random_street(true);
  straight(mid, kK, kM3);
  straight(mid, kM3, kQ);
  straight(random_street(true), kM3, kB3);
  straight(random_street(true), kQ, kR);
  const int west = random_street(true);
  straight(west, kW0, kW1);
  straight(west, kW1, kW2);
}

// Splits the road from node a to node b nearest to `node`'s centre where the node projects
// onto it: the first part ends at the node, the second starts there (same street, bends).
void OrganicPlanner::split_road(int a, int b, int node) {
  const Eigen::Vector2d c = nodes_[static_cast<size_t>(node)].centre;
  size_t best_road = roads_.size(), best_seg = 0;
  double best_d = 1e300;
  Eigen::Vector2d best_p = c;
  for (size_t i = 0; i < roads_.size(); ++i) {
    const RoadPlan& r = roads_[i];
    if (r.ring || r.a != a || r.b != b) continue;
    for (size_t k = 0; k + 1 < r.poly.size(); ++k) {
      const Eigen::Vector2d u = r.poly[k + 1] - r.poly[k];
      const double s = std::clamp((c - r.poly[k]).dot(u) / u.squaredNorm(), 0.0, 1.0);
      const Eigen::Vector2d pt = r.poly[k] + s * u;
      if ((pt - c).norm() < best_d) best_road = i, best_seg = k, best_d = (pt - c).norm(), best_p = pt;
    }
  }
  NSG_CHECK(best_road < roads_.size() && best_d < 20.0, InternalError, "",
            "organic layout: local street node " + std::to_string(node),
            "a plan road from node " + std::to_string(a) + " to " + std::to_string(b) + " passing within 20 m");
  RoadPlan second = roads_[best_road];
  RoadPlan& first = roads_[best_road];
  first.b = node;
  first.poly.resize(best_seg + 1);
  first.poly.push_back(best_p);
  second.a = node;
  second.poly.erase(second.poly.begin(), second.poly.begin() + static_cast<std::ptrdiff_t>(best_seg) + 1);
  second.poly.insert(second.poly.begin(), best_p);
  roads_.insert(roads_.begin() + static_cast<std::ptrdiff_t>(best_road) + 1, std::move(second));
}

// The arm a road makes at one of its nodes: direction out of the node, and how far its
// road edge reaches from the axis through the node centre.
Arm OrganicPlanner::arm(const RoadPlan& r, bool at_a) const {
  const StreetLayout lay = layout_of(streets_[static_cast<size_t>(r.street)], rht_);
  const double edge = std::max(lay.left_edge, -lay.right_edge);
  const Eigen::Vector2d centre = nodes_[static_cast<size_t>(at_a ? r.a : r.b)].centre;
  if (r.ring) {
    const double angle = at_a ? r.angle_a : r.angle_b, sense = rht_ ? 1.0 : -1.0;
    const Eigen::Vector2d tangent = sense * Eigen::Vector2d(-std::sin(angle), std::cos(angle));
    return {at_a ? tangent : Eigen::Vector2d(-tangent), edge};
  }
  const size_t n = r.poly.size();
  const Eigen::Vector2d p = at_a ? r.poly[0] : r.poly[n - 1];
  const Eigen::Vector2d dir = (at_a ? r.poly[1] - r.poly[0] : r.poly[n - 2] - r.poly[n - 1]).normalized();
  const Eigen::Vector2d off = p - centre;
  return {dir, std::fabs(dir.x() * off.y() - dir.y() * off.x()) + edge};
}

std::vector<Arm> OrganicPlanner::arms_of(int node) const {
  std::vector<Arm> out;
  for (const RoadPlan& r : roads_) {
    if (r.a == node) out.push_back(arm(r, true));
    if (r.b == node) out.push_back(arm(r, false));
  }
  return out;
}

void OrganicPlanner::realize(std::vector<Street>& streets, std::vector<Intersection>& nodes,
                             std::vector<Piece>& pieces) {
  streets = streets_;
  nodes.assign(nodes_.size(), Intersection{});
  for (size_t i = 0; i < nodes_.size(); ++i) {
    Intersection& n = nodes[i];
    n.centre = nodes_[i].centre;
    n.kind = nodes_[i].kind;
    const std::vector<Arm> arms = arms_of(static_cast<int>(i));
    n.arms = static_cast<int>(arms.size());
    const bool junction = n.kind == NodeKind::kJunction;
    n.half_m = junction ? junction_radius_m(arms, kCrosswalkDepthM) : nodes_[i].gap_m;
    n.signalized = junction && n.arms >= 4;
    n.own_area = junction;
  }
  const double sense = rht_ ? 1.0 : -1.0;
  for (const RoadPlan& r : roads_) {
    Piece p;
    p.street = r.street;
    p.node_a = r.a;
    p.node_b = r.b;
    const Intersection &na = nodes[static_cast<size_t>(r.a)], &nb = nodes[static_cast<size_t>(r.b)];
    // Crosswalks where a road meets a junction; the ring's own ends have none.
    p.cross_a = na.kind == NodeKind::kJunction && !r.ring;
    p.cross_b = nb.kind == NodeKind::kJunction && !r.ring;
    p.ext_a = na.half_m + (p.cross_a ? kCrosswalkDepthM : 0.0);
    p.ext_b = nb.half_m + (p.cross_b ? kCrosswalkDepthM : 0.0);
    if (r.ring) {
      double sweep = sense * (r.angle_b - r.angle_a);
      while (sweep <= 0.0) sweep += 2.0 * kPi;
      const double start = r.angle_a + sense * p.ext_a / ring_radius_m_;
      const Eigen::Vector2d s = ring_centre_ + ring_radius_m_ * Eigen::Vector2d(std::cos(start), std::sin(start));
      p.prims.push_back({{s.x(), s.y(), start + sense * kPi / 2.0},
                         sweep * ring_radius_m_ - p.ext_a - p.ext_b,
                         sense / ring_radius_m_});
    } else {
      p.prims = polyline_prims(r.poly, p.ext_a, p.ext_b, r.bend_radius_m, r.spiral);
    }
    pieces.push_back(std::move(p));
  }
  // Junction areas: the hull of every arm's curb points where its road meets the area.
  for (size_t i = 0; i < nodes.size(); ++i) {
    Intersection& n = nodes[i];
    if (n.kind != NodeKind::kJunction) continue;
    std::vector<Eigen::Vector2d> pts;
    for (const Piece& p : pieces) {
      const StreetLayout lay = layout_of(streets[static_cast<size_t>(p.street)], rht_);
      for (int end = 0; end < 2; ++end) {
        if ((end == 0 ? p.node_a : p.node_b) != static_cast<int>(i)) continue;
        const double s = end == 0 ? n.half_m - p.ext_a : p.length() + p.ext_b - n.half_m;
        for (double d : {lay.left_edge, lay.right_edge}) pts.push_back(piece_point(p, s, d));
      }
    }
    n.area = convex_hull(pts);
  }
}

// The roundabout's island, then discs of vegetation where no road passes near their
// centre (roads and sidewalks are drawn over their edges).
void OrganicPlanner::choose_parks(const std::vector<Piece>& pieces, const std::vector<Street>& streets,
                                  std::vector<std::pair<Eigen::Vector2d, double>>& parks) {
  parks.push_back({ring_centre_, ring_radius_m_ - city_.lane_width_m / 2.0 - city_.sidewalk_width_m - 0.5});
  std::vector<Eigen::Vector2d> road_pts;
  std::vector<double> road_half;
  for (const Piece& p : pieces) {
    const StreetLayout lay = layout_of(streets[static_cast<size_t>(p.street)], rht_);
    for (const Eigen::Vector2d& q : piece_curve(p, -p.ext_a, p.length() + p.ext_b, 0.0, 5.0)) {
      road_pts.push_back(q);
      road_half.push_back(std::max(lay.left_edge, -lay.right_edge) + city_.sidewalk_width_m);
    }
  }
  const int wanted = static_cast<int>(std::lround(city_.park_fraction * w_ * h_ / 6000.0));
  for (int attempt = 0, made = 0; attempt < 40 * wanted && made < wanted; ++attempt) {
    const double radius = rng_.uniform(15.0, 35.0);
    const Eigen::Vector2d c(rng_.uniform(x0_ + radius, x0_ + w_ - radius),
                            rng_.uniform(y0_ + radius, y0_ + h_ - radius));
    bool clear = true;
    for (size_t k = 0; k < road_pts.size() && clear; ++k) clear = (road_pts[k] - c).norm() > radius + road_half[k];
    for (const auto& [pc, pr] : parks) clear = clear && (pc - c).norm() > pr + radius + 10.0;
    if (!clear) continue;
    parks.push_back({c, radius});
    ++made;
  }
}

void WorldBuilder::make_organic_layout() {
  OrganicPlanner planner(city_, rht_, rng_);
  planner.plan();
  planner.realize(streets_, nodes_, pieces_);
  planner.choose_parks(pieces_, streets_, parks_);
}

}  // namespace nsg::synth::world_detail
