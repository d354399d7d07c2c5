// Every feature of the organic layout, proven by measuring the built lane graph and ground
// (not the planner's own records): skewed, T and Y junctions, a closed one-way ring, lane
// drops and added lanes, a turn pocket, a median between opposite carriageways, a ramp
// that leaves a carriageway and rejoins it, and clothoid-like bends — for both traffic
// sides, on organic-tiny.json and on the demo world (demo.json: the same plan with its
// local streets, city.local_streets).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <tuple>

#include "nsg/geometry/arcline.h"
#include "nsg/synth/config.h"
#include "nsg/synth/world.h"
#include "test_support.h"

namespace nsg::synth {
namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kDeg = kPi / 180.0;

// The sample and the location (its traffic side).
using WorldParam = std::tuple<std::string, std::string>;

SynthConfig organic_config(const WorldParam& param) {
  SynthConfig c = SynthConfig::from_file(test::source_dir() / "samples" / "synth" / std::get<0>(param));
  c.location = std::get<1>(param);
  return c;
}

double end_yaw(const LaneInfo& l) {
  const geometry::ArclinePath& p = l.paths.back();
  return geometry::arcline_pose_at(p, p.length_m()).yaw;
}
double start_yaw(const LaneInfo& l) { return l.paths.front().start_pose.yaw; }
double angle_between(double a, double b) { return std::fabs(geometry::wrap_angle_devkit(a - b)); }
// Heading change along a connector (signed, left positive).
double turn_of(const LaneInfo& c) { return geometry::wrap_angle_devkit(end_yaw(c) - start_yaw(c)); }

// One arm of a place: the lanes arriving from and leaving along one direction.
struct Arm {
  double dir = 0.0;  // out of the place
  int in = 0, out = 0;
};

// A place where connectors join lane ends: a junction or a transition.
struct Place {
  std::vector<int> in, out;  // lanes ending / starting here
  std::vector<Arm> arms;
};

int find(std::vector<int>& parent, int i) {
  while (parent[static_cast<size_t>(i)] != i)
    i = parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
  return i;
}

std::vector<Place> places(const World& w) {
  const int n = static_cast<int>(w.lanes.size());
  std::vector<int> parent(static_cast<size_t>(2 * n));
  std::iota(parent.begin(), parent.end(), 0);
  for (const LaneInfo& c : w.lanes) {
    if (!c.is_connector) continue;
    parent[static_cast<size_t>(find(parent, 2 * c.incoming[0]))] = find(parent, 2 * c.outgoing[0] + 1);
  }
  // Where every lane of an arm turns one way only (a two-lane arm's inner lane left, outer
  // lane right), a junction's connectors fall into groups no connector joins; they still
  // cross or touch each other inside the junction (a left turn crosses the opposing
  // straight movement), which connectors of different places never do.
  std::vector<int> connectors;
  std::vector<std::vector<geometry::Pose2>> lines;
  for (int i = 0; i < n; ++i) {
    if (!w.lanes[static_cast<size_t>(i)].is_connector) continue;
    connectors.push_back(i);
    lines.push_back(lane_polyline(w.lanes[static_cast<size_t>(i)], 1.0));
  }
  auto touch = [](const std::vector<geometry::Pose2>& a, const std::vector<geometry::Pose2>& b) {
    for (const geometry::Pose2& p : a)
      for (const geometry::Pose2& q : b)
        if (std::hypot(p.x - q.x, p.y - q.y) < 1.0) return true;
    return false;
  };
  for (size_t i = 0; i < connectors.size(); ++i) {
    for (size_t j = i + 1; j < connectors.size(); ++j) {
      const int ri = find(parent, 2 * w.lanes[static_cast<size_t>(connectors[i])].incoming[0]);
      const int rj = find(parent, 2 * w.lanes[static_cast<size_t>(connectors[j])].incoming[0]);
      if (ri != rj && touch(lines[i], lines[j])) parent[static_cast<size_t>(ri)] = rj;
    }
  }
  std::map<int, Place> by_root;
  for (int i = 0; i < n; ++i) {
    if (w.lanes[static_cast<size_t>(i)].is_connector) continue;
    by_root[find(parent, 2 * i)].in.push_back(i);
    by_root[find(parent, 2 * i + 1)].out.push_back(i);
  }
  std::vector<Place> out;
  for (auto& [root, place] : by_root) {
    auto add = [&](double dir, bool incoming) {
      for (Arm& a : place.arms) {
        if (angle_between(a.dir, dir) < 15.0 * kDeg) {
          (incoming ? a.in : a.out)++;
          return;
        }
      }
      place.arms.push_back({dir, incoming ? 1 : 0, incoming ? 0 : 1});
    };
    for (int i : place.in) add(end_yaw(w.lanes[static_cast<size_t>(i)]) + kPi, true);
    for (int i : place.out) add(start_yaw(w.lanes[static_cast<size_t>(i)]), false);
    if (!place.in.empty() && !place.out.empty()) out.push_back(std::move(place));
  }
  return out;
}

bool two_way_arms(const Place& p) {
  for (const Arm& a : p.arms)
    if (a.in == 0 || a.out == 0) return false;
  return true;
}

std::vector<geometry::Pose2> polyline(const World& w, int lane) {
  return lane_polyline(w.lanes[static_cast<size_t>(lane)], 1.0);
}

double distance_to(const std::vector<geometry::Pose2>& line, const geometry::Pose2& p) {
  double best = 1e300;
  for (const geometry::Pose2& q : line) best = std::min(best, std::hypot(q.x - p.x, q.y - p.y));
  return best;
}

class OrganicFeatures : public ::testing::TestWithParam<WorldParam> {
 protected:
  void SetUp() override {
    config_ = organic_config(GetParam());
    world_ = build_world(config_, 7);
    places_ = places(world_);
  }
  bool rht() const { return config_.right_hand_traffic(); }
  const LaneInfo& lane(int i) const { return world_.lanes[static_cast<size_t>(i)]; }
  SynthConfig config_;
  World world_;
  std::vector<Place> places_;
};

// Skewed junctions: arms meeting at 45–75°. T: three two-way arms, two collinear, the third
// across them. Y: three two-way arms, none collinear.
TEST_P(OrganicFeatures, SkewedTAndYJunctions) {
  int skewed = 0, t = 0, y = 0;
  for (const Place& p : places_) {
    if (p.arms.size() < 3) continue;
    bool skew = false;
    int collinear = 0;
    for (size_t i = 0; i < p.arms.size(); ++i) {
      for (size_t j = i + 1; j < p.arms.size(); ++j) {
        const double a = angle_between(p.arms[i].dir, p.arms[j].dir);
        skew |= a >= 45.0 * kDeg && a <= 75.0 * kDeg;
        collinear += a > 170.0 * kDeg;
      }
    }
    skewed += skew;
    if (p.arms.size() == 3 && two_way_arms(p)) {
      bool none_near_collinear = true;
      for (size_t i = 0; i < 3; ++i)
        for (size_t j = i + 1; j < 3; ++j)
          none_near_collinear &= angle_between(p.arms[i].dir, p.arms[j].dir) < 160.0 * kDeg;
      t += collinear == 1;
      y += none_near_collinear;
    }
  }
  EXPECT_GE(skewed, 2);
  EXPECT_GE(t, 3);
  EXPECT_GE(y, 1);
}

// The roundabout: one-way lanes of one circle, each continuing into the next through the
// ring's connectors, closing a loop that turns once around (left where traffic keeps
// right); entries join it and exits leave it.
TEST_P(OrganicFeatures, ClosedOneWayRing) {
  auto ring_radius = [&](int i) {
    const LaneInfo& l = lane(i);
    if (l.is_connector || l.two_way_road) return 0.0;
    for (const auto& p : l.paths)
      if (p.radius_m > 60.0 || p.shape != l.paths.front().shape ||
          std::fabs(p.radius_m - l.paths.front().radius_m) > 0.01)
        return 0.0;
    return l.paths.front().radius_m;
  };
  int rings = 0;
  for (int start = 0; start < static_cast<int>(world_.lanes.size()); ++start) {
    const double r = ring_radius(start);
    if (r == 0.0) continue;
    double turning = 0.0;
    int cur = start, steps = 0, entries = 0, exits = 0;
    do {
      const LaneInfo& l = lane(cur);
      turning += l.length_m / r * (l.paths.front().shape == geometry::ArclineShape::kLSL ? 1.0 : -1.0);
      int next = -1;
      for (int c : l.outgoing) {
        const int o = lane(c).outgoing[0];
        if (std::fabs(ring_radius(o) - r) < 0.01) next = o, turning += turn_of(lane(c));
        else ++exits;
      }
      for (int c : l.incoming) entries += std::fabs(ring_radius(lane(c).incoming[0]) - r) >= 0.01;
      cur = next;
    } while (cur >= 0 && cur != start && ++steps < 10);
    if (cur != start) continue;
    EXPECT_NEAR(turning, rht() ? 2.0 * kPi : -2.0 * kPi, 0.05);
    EXPECT_GE(entries, 3);
    EXPECT_GE(exits, 3);
    ++rings;
  }
  EXPECT_GE(rings, 3) << "every lane of the ring closes the loop";
}

// Lane drops and added lanes: places of two collinear arms without junction turns where
// the lanes arriving from one arm outnumber (or are outnumbered by) those leaving along
// the other, joined by merging (or forking) connectors.
TEST_P(OrganicFeatures, LaneDropsAndAddedLanes) {
  int drops = 0, adds = 0;
  for (const Place& p : places_) {
    if (p.arms.size() != 2 || angle_between(p.arms[0].dir, p.arms[1].dir) < 175.0 * kDeg) continue;
    for (int k = 0; k < 2; ++k) {
      const int in = p.arms[static_cast<size_t>(k)].in, out = p.arms[static_cast<size_t>(1 - k)].out;
      if (in == 0) continue;
      drops += in > out;
      adds += in < out;
    }
    for (int i : p.out) {  // a drop shows as a lane with two connectors arriving
      if (lane(i).incoming.size() < 2) continue;
      for (int c : lane(i).incoming) EXPECT_LT(std::fabs(turn_of(lane(c))), 0.3);
    }
  }
  EXPECT_GE(drops, 2);
  EXPECT_GE(adds, 2);
}

// A turn pocket: a lane whose only successors turn across the oncoming traffic, forked off
// the lane before it, with a neighbour beside it going straight through the junction.
TEST_P(OrganicFeatures, TurnPocketOnlyTurns) {
  const double far = rht() ? 1.0 : -1.0;
  int pockets = 0;
  for (const Place& p : places_) {
    for (int i : p.in) {
      const LaneInfo& l = lane(i);
      bool only_far = !l.outgoing.empty();
      for (int c : l.outgoing) only_far &= far * turn_of(lane(c)) > 0.6;
      if (!only_far || l.incoming.size() != 1) continue;
      const LaneInfo& before = lane(lane(l.incoming[0]).incoming[0]);
      if (before.outgoing.size() < 2) continue;
      bool straight_neighbour = false;
      for (int j : p.in) {
        if (j == i || angle_between(end_yaw(lane(j)), end_yaw(l)) > 0.05) continue;
        for (int c : lane(j).outgoing) straight_neighbour |= std::fabs(turn_of(lane(c))) < 0.2;
      }
      pockets += straight_neighbour;
    }
  }
  EXPECT_GE(pockets, 1);
}

// A divided road: one-way lanes side by side in opposite directions with a raised median
// (no drivable ground) between them.
TEST_P(OrganicFeatures, MedianBetweenOppositeCarriageways) {
  int medians = 0;
  const double half = config_.city.lane_width_m / 2.0;
  for (size_t a = 0; a < world_.lanes.size(); ++a) {
    const LaneInfo& la = world_.lanes[a];
    if (la.is_connector || la.two_way_road) continue;
    const std::vector<geometry::Pose2> pa = polyline(world_, static_cast<int>(a));
    const geometry::Pose2 mid = pa[pa.size() / 2];
    for (size_t b = 0; b < world_.lanes.size(); ++b) {
      const LaneInfo& lb = world_.lanes[b];
      if (b == a || lb.is_connector || lb.two_way_road) continue;
      for (const geometry::Pose2& q : polyline(world_, static_cast<int>(b))) {
        const double dx = q.x - mid.x, dy = q.y - mid.y;
        const double along = std::cos(mid.yaw) * dx + std::sin(mid.yaw) * dy;
        const double across = -std::sin(mid.yaw) * dx + std::cos(mid.yaw) * dy;
        if (std::fabs(along) > 0.6 || std::fabs(across) > 15.0 || angle_between(q.yaw, mid.yaw + kPi) > 0.05) continue;
        bool raised = false;
        for (double d = half + 0.3; d < std::fabs(across) - half - 0.3; d += 0.1) {
          const double s = across > 0 ? d : -d;
          const GroundMaterial m =
              world_.ground->material(mid.x - std::sin(mid.yaw) * s, mid.y + std::cos(mid.yaw) * s);
          raised |= !is_drivable_material(m);
        }
        medians += raised;
      }
    }
  }
  EXPECT_GE(medians, 4);
}

// A ramp: a one-way lane forked off a carriageway lane that swings out more than 10 m from
// the carriageway and merges back into it further on.
TEST_P(OrganicFeatures, RampLeavesAndRejoins) {
  int ramps = 0;
  for (size_t r = 0; r < world_.lanes.size(); ++r) {
    const LaneInfo& ramp = world_.lanes[r];
    if (ramp.is_connector || ramp.two_way_road || ramp.incoming.size() != 1 || ramp.outgoing.size() != 1) continue;
    const LaneInfo& fork_lane = lane(lane(ramp.incoming[0]).incoming[0]);
    const int rejoin = lane(ramp.outgoing[0]).outgoing[0];
    for (int c : fork_lane.outgoing) {
      const int main = lane(c).outgoing[0];
      if (main == static_cast<int>(r) || lane(main).two_way_road) continue;
      // Along the carriageway (straight on, at most 6 lanes) to where the ramp rejoins.
      std::vector<int> chain = {main};
      while (chain.back() != rejoin && chain.size() < 6) {
        int next = -1;
        for (int k : lane(chain.back()).outgoing)
          if (std::fabs(turn_of(lane(k))) < 0.2) next = lane(k).outgoing[0];
        if (next < 0) break;
        chain.push_back(next);
      }
      if (chain.back() != rejoin) continue;
      const std::vector<geometry::Pose2> pr = polyline(world_, static_cast<int>(r));
      double apart = 1e300;
      for (int k : chain) apart = std::min(apart, distance_to(polyline(world_, k), pr[pr.size() / 2]));
      ramps += apart > 10.0;
    }
  }
  EXPECT_GE(ramps, 1);
}

// Curved arterials: many arcs, and bends run in and out like clothoids — at least seven
// consecutive arcs turning one way whose curvature rises, then falls.
TEST_P(OrganicFeatures, ClothoidLikeBends) {
  int curved = 0, clothoids = 0;
  for (const LaneInfo& l : world_.lanes) {
    if (l.is_connector) continue;
    bool arc = false;
    for (const auto& p : l.paths) arc |= p.radius_m < 500.0;
    curved += arc;
    for (size_t k = 0; k + 7 <= l.paths.size(); ++k) {
      bool ok = true;
      for (size_t j = k; j < k + 7; ++j) ok &= l.paths[j].radius_m < 500.0 && l.paths[j].shape == l.paths[k].shape;
      for (size_t j = k; j < k + 3 && ok; ++j) ok &= l.paths[j + 1].radius_m < l.paths[j].radius_m;
      for (size_t j = k + 3; j < k + 6 && ok; ++j) ok &= l.paths[j + 1].radius_m > l.paths[j].radius_m;
      clothoids += ok;
    }
  }
  EXPECT_GE(curved, 12);
  EXPECT_GE(clothoids, 8);
}

INSTANTIATE_TEST_SUITE_P(BothTrafficSides, OrganicFeatures,
                         ::testing::Combine(::testing::Values("organic-tiny.json", "demo.json"),
                                            ::testing::Values("boston-seaport", "singapore-onenorth")),
                         [](const ::testing::TestParamInfo<WorldParam>& info) {
                           return std::string(std::get<0>(info.param) == "demo.json" ? "Demo" : "Tiny") +
                                  (std::get<1>(info.param) == "boston-seaport" ? "RightHand" : "LeftHand");
                         });

}  // namespace
}  // namespace nsg::synth
