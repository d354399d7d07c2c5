// The synthetic world without files: config parsing, lane graph geometry, traffic side.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/rng.h"
#include "nsg/geometry/arcline.h"
#include "nsg/synth/config.h"
#include "nsg/synth/world.h"
#include "test_support.h"

namespace nsg::synth {
namespace {

SynthConfig tiny_config() { return SynthConfig::from_file(test::source_dir() / "samples" / "synth" / "tiny.json"); }

TEST(WorldConfig, UnknownKeyIsRejectedNamingIt) {
  try {
    SynthConfig::from_json_text(R"({"location": "boston-seaport", "city": {"blokcs_x": 3}})", "cfg.json");
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "cfg.json");
    EXPECT_EQ(e.record(), "city.blokcs_x");
  }
  EXPECT_THROW(SynthConfig::from_json_text(R"({"location": "paris"})", "cfg.json"), ConfigError);
  EXPECT_THROW(SynthConfig::from_json_text(R"({"scenes": {"count": 0}})", "cfg.json"), ConfigError);
  EXPECT_THROW(SynthConfig::from_json_text(R"({"lidar": {"beams": "many"}})", "cfg.json"), ConfigError);
  EXPECT_THROW(SynthConfig::from_json_text(R"({"seed": -1})", "cfg.json"), ConfigError);
  EXPECT_THROW(SynthConfig::from_json_text(R"({"city": {"blocks_x": 2.5}})", "cfg.json"), ConfigError);
  EXPECT_THROW(SynthConfig::from_json_text("{", "cfg.json"), ParseError);
}

TEST(WorldConfig, SamplesParseAndTrafficSideFollowsLocation) {
  for (const char* name : {"tiny.json", "demo.json", "demo-grid.json", "bench.json"}) {
    const SynthConfig c = SynthConfig::from_file(test::source_dir() / "samples" / "synth" / name);
    EXPECT_NO_THROW(c.validate()) << name;
  }
  SynthConfig c;
  c.location = "boston-seaport";
  EXPECT_TRUE(c.right_hand_traffic());
  c.location = "singapore-onenorth";
  EXPECT_FALSE(c.right_hand_traffic());
}

TEST(WorldDubins, PathEndsAtTheTargetPose) {
  Rng rng(3);
  for (int i = 0; i < 200; ++i) {
    const geometry::Pose2 a{rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-3.1, 3.1)};
    const geometry::Pose2 b{rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-3.1, 3.1)};
    const double r = rng.uniform(3.0, 15.0);
    const geometry::ArclinePath p = dubins_path(a, b, r);
    const geometry::Pose2 e = geometry::arcline_pose_at(p, p.length_m());
    EXPECT_LT(std::hypot(e.x - b.x, e.y - b.y), 1e-6);
    EXPECT_LT(std::fabs(geometry::wrap_angle_devkit(e.yaw - b.yaw)), 1e-6);
  }
}

// Lane ends meet the starts of their successors (≤ 1 cm) with the devkit discretization,
// connectivity mirrors, and intersections have forks and merges.
TEST(WorldLaneGraph, ArclineEndsMeetOutgoingStarts) {
  const World w = build_world(tiny_config(), 7);
  size_t edges = 0, forks = 0, merges = 0, turns = 0;
  for (size_t i = 0; i < w.lanes.size(); ++i) {
    const LaneInfo& a = w.lanes[i];
    const std::vector<geometry::Pose2> pa = geometry::discretize_lane(a.paths, 0.5);
    ASSERT_GE(pa.size(), 2u);
    if (a.outgoing.size() > 1) ++forks;
    if (a.incoming.size() > 1) ++merges;
    EXPECT_FALSE(a.outgoing.empty()) << "dead end " << a.token;
    for (int o : a.outgoing) {
      const LaneInfo& b = w.lanes[static_cast<size_t>(o)];
      const std::vector<geometry::Pose2> pb = geometry::discretize_lane(b.paths, 0.5);
      EXPECT_LE(std::hypot(pa.back().x - pb.front().x, pa.back().y - pb.front().y), 0.01)
          << a.token << " -> " << b.token;
      EXPECT_LE(std::fabs(geometry::wrap_angle_devkit(pa.back().yaw - pb.front().yaw)), 1e-3);
      EXPECT_NE(std::find(b.incoming.begin(), b.incoming.end(), static_cast<int>(i)), b.incoming.end());
      if (b.is_connector &&
          std::fabs(geometry::wrap_angle_devkit(b.paths.back().end_pose.yaw - b.paths.front().start_pose.yaw)) > 1.0)
        ++turns;
      ++edges;
    }
  }
  EXPECT_GT(edges, 50u);
  EXPECT_GT(forks, 0u);
  EXPECT_GT(merges, 0u);
  EXPECT_GT(turns, 4u);
}

// Other seeds, sizes and traffic sides: connectors always meet their lanes (build_world
// throws otherwise) and no lane is a dead end.
TEST(WorldLaneGraph, ManySeedsBuildWithoutDeadEnds) {
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    SynthConfig c = tiny_config();
    c.location = seed % 2 ? "singapore-hollandvillage" : "boston-seaport";
    c.city.blocks_x = 3;
    c.city.max_lanes_per_direction = 1 + static_cast<int>(seed % 3);
    c.city.one_way_fraction = 0.5;
    c.map_size_m = {400.0, 300.0};
    const World w = build_world(c, seed);
    size_t lanes = 0;
    for (const LaneInfo& lane : w.lanes) {
      EXPECT_FALSE(lane.outgoing.empty()) << "seed " << seed << " lane " << lane.token;
      EXPECT_FALSE(lane.incoming.empty()) << "seed " << seed << " lane " << lane.token;
      lanes += !lane.is_connector;
    }
    EXPECT_GT(lanes, 12u);
    EXPECT_FALSE(w.buildings.empty());
    EXPECT_FALSE(w.parking_slots.empty() && c.city.parking_fraction > 0.9);
  }
}

// The centre divider of a two-way road lies on the driver's left for right-hand traffic
// (boston-seaport) and on the right for left-hand traffic (singapore-*); in Boston the
// centre paint is yellow.
TEST(WorldLaneGraph, TrafficKeepsToTheConfiguredSide) {
  for (const std::string location : {"boston-seaport", "singapore-onenorth"}) {
    SynthConfig c = tiny_config();
    c.location = location;
    const World w = build_world(c, 11);
    const nlohmann::json map = nlohmann::json::parse(w.map_json);
    std::map<std::string, std::pair<double, double>> nodes;
    for (const auto& n : map["node"]) nodes[n["token"]] = {n["x"], n["y"]};
    std::map<std::string, std::vector<std::string>> lines;
    for (const auto& l : map["line"]) lines[l["token"]] = l["node_tokens"].get<std::vector<std::string>>();
    std::vector<std::pair<double, double>> divider_pts;
    for (const auto& d : map["road_divider"])
      for (const auto& t : lines.at(d["line_token"])) divider_pts.push_back(nodes.at(t));
    ASSERT_FALSE(divider_pts.empty());
    int checked = 0;
    for (const LaneInfo& lane : w.lanes) {
      if (lane.is_connector || !lane.two_way_road) continue;
      const std::vector<geometry::Pose2> poly = lane_polyline(lane, 1.0);
      const geometry::Pose2 mid = poly[poly.size() / 2];
      double best = 1e9, side = 0.0;
      for (const auto& [x, y] : divider_pts) {
        const double dx = x - mid.x, dy = y - mid.y, d = std::hypot(dx, dy);
        if (d < best) best = d, side = std::cos(mid.yaw) * dy - std::sin(mid.yaw) * dx;
      }
      ASSERT_LT(best, 12.0);
      if (c.right_hand_traffic()) {
        EXPECT_GT(side, 0.0) << location << " lane " << lane.token << " has the centre line on its right";
        // Walking left from the lane centre reaches yellow paint before any curb.
        GroundMaterial first = GroundMaterial::kAsphalt;
        for (double d = 0.0; d < 12.0; d += 0.05) {
          const GroundMaterial m = w.ground->material(mid.x - std::sin(mid.yaw) * d, mid.y + std::cos(mid.yaw) * d);
          if (m == GroundMaterial::kPaintYellow || m == GroundMaterial::kCurbTop) {
            first = m;
            break;
          }
        }
        EXPECT_EQ(first, GroundMaterial::kPaintYellow) << lane.token;
      } else {
        EXPECT_LT(side, 0.0) << location << " lane " << lane.token << " has the centre line on its left";
      }
      ++checked;
    }
    EXPECT_GT(checked, 4) << location;
  }
}

TEST(WorldMap, EveryLayerPresentAndReferencesResolve) {
  const World w = build_world(tiny_config(), 7);
  const nlohmann::json map = nlohmann::json::parse(w.map_json);
  EXPECT_EQ(map["version"], "1.3");
  for (const char* layer :
       {"polygon", "line", "node", "drivable_area", "road_segment", "road_block", "lane", "ped_crossing", "walkway",
        "stop_line", "carpark_area", "road_divider", "lane_divider", "traffic_light", "lane_connector"}) {
    ASSERT_TRUE(map.contains(layer)) << layer;
    EXPECT_FALSE(map[layer].empty()) << layer;
  }
  ASSERT_TRUE(map.contains("arcline_path_3"));
  ASSERT_TRUE(map.contains("connectivity"));
  ASSERT_TRUE(map.contains("canvas_edge"));
  std::set<std::string> nodes, lines, polys;
  for (const auto& n : map["node"]) {
    const std::string t = n["token"];
    EXPECT_EQ(t.size(), 36u);
    EXPECT_EQ(t[8], '-');
    nodes.insert(t);
  }
  for (const auto& l : map["line"]) {
    lines.insert(l["token"].get<std::string>());
    for (const auto& t : l["node_tokens"]) EXPECT_TRUE(nodes.count(t)) << t;
  }
  for (const auto& p : map["polygon"]) {
    polys.insert(p["token"].get<std::string>());
    for (const auto& t : p["exterior_node_tokens"]) EXPECT_TRUE(nodes.count(t)) << t;
  }
  for (const char* layer :
       {"road_segment", "road_block", "lane", "ped_crossing", "walkway", "stop_line", "carpark_area", "lane_connector"})
    for (const auto& r : map[layer]) EXPECT_TRUE(polys.count(r["polygon_token"])) << layer;
  for (const char* layer : {"road_divider", "lane_divider", "traffic_light"})
    for (const auto& r : map[layer]) EXPECT_TRUE(lines.count(r["line_token"])) << layer;
  for (const auto& r : map["lane"])
    for (const char* k : {"left_lane_divider_segments", "right_lane_divider_segments"})
      for (const auto& s : r[k]) EXPECT_TRUE(nodes.count(s["node_token"]));
  bool intersection = false;
  for (const auto& r : map["road_segment"]) intersection |= r["is_intersection"].get<bool>();
  EXPECT_TRUE(intersection);
  // Every lane and connector has arcline paths and a connectivity record.
  const size_t n = map["lane"].size() + map["lane_connector"].size();
  EXPECT_EQ(map["arcline_path_3"].size(), n);
  EXPECT_EQ(map["connectivity"].size(), n);
  bool curved = false;
  for (const auto& [tok, paths] : map["arcline_path_3"].items())
    for (const auto& p : paths) curved |= p["radius"].get<double>() < 100.0;
  EXPECT_TRUE(curved);
}

}  // namespace
}  // namespace nsg::synth
