// Map changes (changes.h): the world builder's world, then the same world after seeded
// atomic edits. The prior is what build() returns; the edits run after every record of it
// was made, on a random stream of their own, so the prior's records and tokens never depend
// on them. Each edit kind picks its places among the world's own (lanes of a group, turning
// connectors, junctions' lane pairs, dividers, mid-block stretches), each ≥ kMinEditSpacingM
// from the earlier edits, in the order of kMapEditKinds.
#include <algorithm>
#include <cmath>
#include <memory>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "world_builder.h"

namespace nsg::synth::world_detail {

namespace {

// Barriers along a closed lane: one every kBarrierSpacingM, a jersey barrier's size, orange.
constexpr double kBarrierSpacingM = 5.0;
constexpr double kBarrierLengthM = 1.8, kBarrierWidthM = 0.5, kBarrierHeightM = 0.9;
// A turn: a connector whose heading changes by more than this (straight-through ones stay).
constexpr double kTurnDeg = 30.0;
// A closed lane and a mid-block crossing's piece are at least this long.
constexpr double kMinClosedLaneM = 30.0, kMinCrossingPieceM = 40.0;
constexpr double kCrossingDepthM = 4.0;

Eigen::Vector2d mid_point(const LaneInfo& lane) {
  const std::vector<Pose2> poly = lane_polyline(lane, 1.0);
  const Pose2& p = poly[poly.size() / 2];
  return {p.x, p.y};
}

double heading_change_deg(const LaneInfo& lane) {
  const double a = lane.paths.front().start_pose.yaw, b = lane.paths.back().end_pose.yaw;
  return std::fabs(std::remainder(b - a, 2.0 * kPi)) * 180.0 / kPi;
}

// Takes `count` of `candidates` (indices) in a seeded order, each far from the earlier edits;
// `accept` may still refuse one (it then stays unused). ConfigError naming `key` when fewer
// than `count` could be taken.
template <class Accept>
void pick(Rng& rng, std::vector<int> candidates, int count, const char* key, Accept&& accept) {
  rng.shuffle(candidates);
  int taken = 0;
  for (const int c : candidates) {
    if (taken == count) break;
    taken += accept(c) ? 1 : 0;
  }
  NSG_CHECK(taken == count, ConfigError, "", key,
            strprintf("at most %d for this world: it has room for no more such edits %.0f m or more from every "
                      "other edit",
                      taken, kMinEditSpacingM));
}

// World::lanes without the `removed` ones, every outgoing/incoming index renumbered.
void drop_lanes(std::vector<LaneInfo>& lanes, const std::vector<bool>& removed) {
  std::vector<int> renumber(lanes.size(), -1);
  int next = 0;
  for (size_t i = 0; i < lanes.size(); ++i)
    if (!removed[i]) renumber[i] = next++;
  std::vector<LaneInfo> kept;
  for (size_t i = 0; i < lanes.size(); ++i) {
    if (removed[i]) continue;
    LaneInfo lane = std::move(lanes[i]);
    for (std::vector<int>* links : {&lane.outgoing, &lane.incoming}) {
      std::vector<int> out;
      for (const int j : *links)
        if (renumber[static_cast<size_t>(j)] >= 0) out.push_back(renumber[static_cast<size_t>(j)]);
      *links = std::move(out);
    }
    kept.push_back(std::move(lane));
  }
  lanes = std::move(kept);
}

}  // namespace

bool WorldBuilder::far_from_edits(const std::vector<MapEdit>& edits, const Eigen::Vector2d& p) const {
  return std::all_of(edits.begin(), edits.end(), [&](const MapEdit& e) {
    return std::hypot(e.at_m[0] - p.x(), e.at_m[1] - p.y()) >= kMinEditSpacingM;
  });
}

// A lane of a group of two or more (never a turn pocket), closed: it and every connector
// into or out of it leave the map, barriers stand along it; its paint stays.
std::vector<int> WorldBuilder::close_lanes(Rng& rng, std::vector<MapEdit>& edits, std::vector<bool>& removed) {
  std::vector<int> candidates, closed;
  for (size_t i = 0; i < builds_.size(); ++i)
    if (builds_[i].group_size >= 2 && !builds_[i].pocket && world_.lanes[i].length_m >= kMinClosedLaneM)
      candidates.push_back(static_cast<int>(i));
  pick(rng, candidates, cfg_.changes.lanes_closed, "changes.lanes_closed", [&](int i) {
    const LaneInfo& lane = world_.lanes[static_cast<size_t>(i)];
    const Eigen::Vector2d at = mid_point(lane);
    if (!far_from_edits(edits, at)) return false;
    MapEdit e{"lane_closed", {lane.token}, {}, {}, {at.x(), at.y()}};
    removed[static_cast<size_t>(i)] = true;
    for (const std::vector<int>* links : {&lane.incoming, &lane.outgoing})
      for (const int c : *links)
        if (world_.lanes[static_cast<size_t>(c)].is_connector && !removed[static_cast<size_t>(c)]) {
          removed[static_cast<size_t>(c)] = true;
          e.removed.push_back(world_.lanes[static_cast<size_t>(c)].token);
        }
    edits.push_back(std::move(e));
    closed.push_back(i);
    return true;
  });
  return closed;
}

// A turning connector whose lane keeps another way on: it leaves the map, and the traffic
// planned on the changed world never takes it.
void WorldBuilder::remove_turns(Rng& rng, std::vector<MapEdit>& edits, std::vector<bool>& removed) {
  std::vector<int> candidates;
  for (size_t i = 0; i < world_.lanes.size(); ++i)
    if (world_.lanes[i].is_connector && !removed[i] && heading_change_deg(world_.lanes[i]) > kTurnDeg)
      candidates.push_back(static_cast<int>(i));
  pick(rng, candidates, cfg_.changes.turns_removed, "changes.turns_removed", [&](int i) {
    const LaneInfo& turn = world_.lanes[static_cast<size_t>(i)];
    if (turn.incoming.size() != 1) return false;
    const LaneInfo& from = world_.lanes[static_cast<size_t>(turn.incoming.front())];
    const auto other_ways = std::count_if(from.outgoing.begin(), from.outgoing.end(),
                                          [&](int o) { return o != i && !removed[static_cast<size_t>(o)]; });
    const Eigen::Vector2d at = mid_point(turn);
    if (other_ways == 0 || !far_from_edits(edits, at)) return false;
    removed[static_cast<size_t>(i)] = true;
    edits.push_back(MapEdit{"turn_removed", {turn.token}, {}, {}, {at.x(), at.y()}});
    return true;
  });
}

// A turning connector a junction did not have, from a lane to an arm it did not reach
// (another piece, turning by 30° to 150°): mapped, and the traffic of the changed world may
// take it.
void WorldBuilder::add_turns(Rng& rng, std::vector<MapEdit>& edits, std::vector<bool>& removed) {
  std::vector<std::pair<int, int>> pairs;
  for (size_t a = 0; a < builds_.size(); ++a)
    for (size_t b = 0; b < builds_.size(); ++b) {
      const int node = builds_[a].end_node;
      if (removed[a] || removed[b] || node < 0 || builds_[b].start_node != node ||
          nodes_[static_cast<size_t>(node)].kind != NodeKind::kJunction || builds_[a].piece == builds_[b].piece)
        continue;
      const ArclinePath& last = world_.lanes[a].paths.back();
      const double from_yaw = geometry::arcline_pose_at(last, last.length_m()).yaw;
      const double turn =
          std::fabs(std::remainder(world_.lanes[b].paths.front().start_pose.yaw - from_yaw, 2.0 * kPi)) * 180.0 / kPi;
      const bool linked = std::any_of(world_.lanes[a].outgoing.begin(), world_.lanes[a].outgoing.end(), [&](int c) {
        const std::vector<int>& next = world_.lanes[static_cast<size_t>(c)].outgoing;
        return c == static_cast<int>(b) || std::find(next.begin(), next.end(), static_cast<int>(b)) != next.end();
      });
      if (turn > kTurnDeg && turn < 150.0 && !linked) pairs.emplace_back(static_cast<int>(a), static_cast<int>(b));
    }
  std::vector<int> candidates(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) candidates[i] = static_cast<int>(i);
  pick(rng, candidates, cfg_.changes.turns_added, "changes.turns_added", [&](int i) {
    const auto [a, b] = pairs[static_cast<size_t>(i)];
    // Far from the other edits: a junction gets one new turn at most.
    const ArclinePath& last = world_.lanes[static_cast<size_t>(a)].paths.back();
    const Pose2 end = geometry::arcline_pose_at(last, last.length_m());
    if (!far_from_edits(edits, {end.x, end.y})) return false;
    try {
      add_connector(a, b);  // throws before it adds anything when no Dubins path meets the lane
    } catch (const InternalError&) {
      return false;
    }
    removed.push_back(false);
    const LaneInfo& turn = world_.lanes.back();
    const Eigen::Vector2d at = mid_point(turn);
    edits.push_back(MapEdit{"turn_added", {}, {turn.token}, {}, {at.x(), at.y()}});
    return true;
  });
}

// A dashed divider between the two lanes of one direction made solid (no more lane
// changes there): the gaps painted, the divider's and both lanes' segments retyped.
void WorldBuilder::retype_dividers(Rng& rng, std::vector<MapEdit>& edits, const std::vector<bool>& removed,
                                   GroundRaster& ground) {
  std::vector<int> candidates;
  // Two-way streets only: on a one-way street of two lanes the lanes' records type their
  // shared side NIL (the dividers' own records and paint say dashed), so there is no dashed
  // segment of theirs to retype.
  for (size_t i = 0; i < dividers_.size(); ++i) {
    const Piece& piece = pieces_[static_cast<size_t>(dividers_[i].piece)];
    if (dividers_[i].group_size == 2 && streets_[static_cast<size_t>(piece.street)].two_way() &&
        piece.length() >= kMinClosedLaneM)
      candidates.push_back(static_cast<int>(i));
  }
  pick(rng, candidates, cfg_.changes.dividers_retyped, "changes.dividers_retyped", [&](int i) {
    const DividerBuild& d = dividers_[static_cast<size_t>(i)];
    const Piece& piece = pieces_[static_cast<size_t>(d.piece)];
    std::vector<std::string> lanes;
    for (size_t l = 0; l < builds_.size(); ++l)
      if (builds_[l].piece == d.piece && builds_[l].forward == d.forward) {
        if (removed[l]) return false;  // a closed lane's group keeps its paint
        lanes.push_back(world_.lanes[l].token);
      }
    const Eigen::Vector2d at = piece_point(piece, piece.length() / 2.0, d.offset_ref);
    if (!far_from_edits(edits, at)) return false;
    map_.retype_lane_divider(d.token, lanes, "SINGLE_DASHED_WHITE", "SINGLE_SOLID_WHITE");
    paint_solid_divider(ground, piece, d.offset_ref);
    std::vector<std::string> retyped = {d.token};
    retyped.insert(retyped.end(), lanes.begin(), lanes.end());
    edits.push_back(MapEdit{"divider_retyped", {}, {}, retyped, {at.x(), at.y()}});
    return true;
  });
}

// A pedestrian crossing half-way along a piece of 40 m or more, across the whole road: its
// stripes painted, a ped_crossing of the piece's road segment in the map.
void WorldBuilder::add_crossings(Rng& rng, std::vector<MapEdit>& edits, GroundRaster& ground) {
  std::vector<int> candidates;
  for (size_t pi = 0; pi < pieces_.size(); ++pi)
    if (pieces_[pi].length() >= kMinCrossingPieceM) candidates.push_back(static_cast<int>(pi));
  pick(rng, candidates, cfg_.changes.crossings_added, "changes.crossings_added", [&](int pi) {
    const Piece& piece = pieces_[static_cast<size_t>(pi)];
    const StreetLayout lay = layout_of(streets_[static_cast<size_t>(piece.street)], rht_);
    // The prim holding the piece's middle, and the middle's s on it.
    double s = piece.length() / 2.0;
    size_t k = 0;
    while (k + 1 < piece.prims.size() && s > piece.prims[k].length) s -= piece.prims[k++].length;
    const Prim& prim = piece.prims[k];
    const double s0 = s - kCrossingDepthM / 2.0, s1 = s + kCrossingDepthM / 2.0;
    if (s0 < 0.0 || s1 > prim.length) return false;  // the crossing stays on one prim
    const Eigen::Vector2d at = prim_point(prim, s, 0.0);
    if (!far_from_edits(edits, at)) return false;
    paint_mid_block_crossing(ground, prim, s0, s1, lay);
    const std::string token =
        map_.ped_crossing({prim_point(prim, s0, lay.right_edge), prim_point(prim, s1, lay.right_edge),
                           prim_point(prim, s1, lay.left_edge), prim_point(prim, s0, lay.left_edge)},
                          piece_segment_[static_cast<size_t>(pi)]);
    edits.push_back(MapEdit{"crossing_added", {}, {token}, {}, {at.x(), at.y()}});
    return true;
  });
}

ChangedWorld WorldBuilder::build_changed() {
  ChangedWorld out;
  out.prior = build();  // moves world_ out; its parts are copied back for the edits
  world_ = out.prior;
  Rng rng(seed_, 0x63'68'6e'67);  // "chng": a stream of its own
  std::vector<bool> removed(world_.lanes.size(), false);
  const std::vector<int> closed = close_lanes(rng, out.edits, removed);
  remove_turns(rng, out.edits, removed);
  add_turns(rng, out.edits, removed);
  auto ground = std::make_shared<GroundRaster>(*world_.ground);
  retype_dividers(rng, out.edits, removed, *ground);
  add_crossings(rng, out.edits, *ground);
  world_.ground = ground;
  for (const int i : closed) {
    const std::vector<Pose2> poly = lane_polyline(world_.lanes[static_cast<size_t>(i)], 0.5);
    double along = 0.0, next = kBarrierSpacingM / 2.0;
    for (size_t p = 1; p < poly.size(); ++p) {
      along += std::hypot(poly[p].x - poly[p - 1].x, poly[p].y - poly[p - 1].y);
      if (along < next) continue;
      next += kBarrierSpacingM;
      SceneBox b;
      b.center_m = {poly[p].x, poly[p].y, kBarrierHeightM / 2.0};
      b.yaw_rad = poly[p].yaw;
      b.length_m = kBarrierLengthM;
      b.width_m = kBarrierWidthM;
      b.height_m = kBarrierHeightM;
      b.cls = SemanticClass::kPoleSign;  // lidarseg static.manmade: a road barrier
      b.lidar_intensity = 110;
      b.rgb = {230, 120, 40};
      world_.buildings.push_back(b);
    }
  }
  for (size_t i = 0; i < removed.size(); ++i)
    if (removed[i]) map_.remove_lane_record(world_.lanes[i].token);
  drop_lanes(world_.lanes, removed);
  world_.map_json = map_.to_json(cfg_.map_size_m, world_lanes_json_order());
  out.current = std::move(world_);
  return out;
}

}  // namespace nsg::synth::world_detail

namespace nsg::synth {

ChangedWorld build_changed_world(const SynthConfig& config, uint64_t seed) {
  config.validate();
  world_detail::WorldBuilder builder(config, seed);
  return builder.build_changed();
}

}  // namespace nsg::synth
