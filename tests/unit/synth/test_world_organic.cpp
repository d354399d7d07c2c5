// The organic layout (city.layout = "organic"): its config checks, and for many seeds and
// both traffic sides a lane graph without dead ends whose connectors meet their lanes with
// the devkit discretization; junction areas that follow their arms; traffic that drives it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "nsg/geometry/arcline.h"
#include "nsg/synth/config.h"
#include "nsg/synth/traffic.h"
#include "nsg/synth/world.h"
#include "test_support.h"

namespace nsg::synth {
namespace {

SynthConfig organic_config() {
  return SynthConfig::from_file(test::source_dir() / "samples" / "synth" / "organic-tiny.json");
}

// The properties test_world_map.cpp checks on the grid: every lane and connector has a
// predecessor and a successor, ends meet starts within 1 cm and 1e-3 rad with the devkit
// discretization, connectivity is mirrored.
void expect_connected(const World& w, const std::string& what) {
  for (size_t i = 0; i < w.lanes.size(); ++i) {
    const LaneInfo& a = w.lanes[i];
    EXPECT_FALSE(a.outgoing.empty()) << what << ": dead end " << a.token;
    EXPECT_FALSE(a.incoming.empty()) << what << ": unreachable " << a.token;
    const std::vector<geometry::Pose2> pa = geometry::discretize_lane(a.paths, 0.5);
    ASSERT_GE(pa.size(), 2u);
    for (int o : a.outgoing) {
      const LaneInfo& b = w.lanes[static_cast<size_t>(o)];
      const std::vector<geometry::Pose2> pb = geometry::discretize_lane(b.paths, 0.5);
      EXPECT_LE(std::hypot(pa.back().x - pb.front().x, pa.back().y - pb.front().y), 0.01)
          << what << ": " << a.token << " -> " << b.token;
      EXPECT_LE(std::fabs(geometry::wrap_angle_devkit(pa.back().yaw - pb.front().yaw)), 1e-3)
          << what << ": " << a.token << " -> " << b.token;
      EXPECT_NE(std::find(b.incoming.begin(), b.incoming.end(), static_cast<int>(i)), b.incoming.end());
      EXPECT_NE(a.is_connector, b.is_connector) << what << ": lanes and connectors alternate";
    }
  }
}

TEST(OrganicConfig, LayoutIsAChoiceAndItsLimitsNameTheKey) {
  EXPECT_EQ(SynthConfig{}.city.layout, CityLayout::kGrid);
  EXPECT_EQ(organic_config().city.layout, CityLayout::kOrganic);
  auto rejected_key = [](const std::string& text) {
    try {
      SynthConfig::from_json_text(text, "cfg.json");
    } catch (const ConfigError& e) {
      return e.record();
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(rejected_key(R"({"city": {"layout": "spaghetti"}})"), "city.layout");
  EXPECT_EQ(rejected_key(R"({"city": {"layout": 2}})"), "city.layout");
  const std::string base = R"({"map_size_m": [600, 400], "city": {"layout": "organic", "origin_m": [40, 40], )";
  EXPECT_EQ(rejected_key(base + R"("blocks_x": 5, "blocks_y": 3, "block_size_m": 100, "max_lanes_per_direction": 1}})"),
            "city.max_lanes_per_direction");
  EXPECT_EQ(rejected_key(base + R"("blocks_x": 5, "blocks_y": 2, "block_size_m": 100}})"), "city.blocks_y");
  EXPECT_EQ(rejected_key(base + R"("blocks_x": 3, "blocks_y": 3, "block_size_m": 100}})"), "city.blocks_x");
  EXPECT_EQ(rejected_key(base + R"("blocks_x": 5, "blocks_y": 3, "block_size_m": 100}})"), "(accepted)");
}

TEST(OrganicConfig, SamplesParse) {
  for (const char* name : {"organic-tiny.json", "demo.json"}) {
    const SynthConfig c = SynthConfig::from_file(test::source_dir() / "samples" / "synth" / name);
    EXPECT_NO_THROW(c.validate()) << name;
    EXPECT_EQ(c.city.layout, CityLayout::kOrganic) << name;
  }
}

// Many seeds, both traffic sides, three lane maxima and two sizes: build_world throws if
// a Dubins connector misses its lane, and no lane is a dead end.
TEST(OrganicLaneGraph, ManySeedsAndBothSidesBuildWithoutDeadEnds) {
  for (uint64_t seed = 1; seed <= 16; ++seed) {
    SynthConfig c = organic_config();
    c.location = seed % 2 ? "singapore-onenorth" : "boston-seaport";
    c.city.max_lanes_per_direction = seed % 3 ? 2 : 3;
    c.city.parking_fraction = seed % 4 == 0 ? 1.0 : 0.5;
    if (seed % 5 == 0) {  // a larger, wider city
      c.map_size_m = {1000.0, 600.0};
      c.city.origin_m = {60.0, 60.0};
      c.city.blocks_x = 13;
      c.city.blocks_y = 7;
      c.city.block_size_m = 70.0;
    }
    const std::string what = c.location + " seed " + std::to_string(seed);
    const World w = build_world(c, seed);
    expect_connected(w, what);
    size_t lanes = 0;
    for (const LaneInfo& lane : w.lanes) lanes += !lane.is_connector;
    EXPECT_GT(lanes, 50u) << what;
    EXPECT_GT(w.buildings.size(), 10u) << what;
    EXPECT_GT(w.poles.size(), 20u) << what;
    EXPECT_GT(w.sidewalks.size(), 20u) << what;
  }
}

// The corners of the accepted sizes (300 m tall, 1.2 to 3 times as wide) and a taller city
// build with every feature in place and the same connection properties.
TEST(OrganicLaneGraph, SizesAtTheLimitsBuild) {
  const std::vector<std::array<int, 2>> blocks = {{6, 5}, {15, 5}, {12, 10}};
  for (const auto& [bx, by] : blocks) {
    SynthConfig c = organic_config();
    c.city.blocks_x = bx;
    c.city.blocks_y = by;
    c.city.block_size_m = 60.0;
    c.city.ground_resolution_m = 0.2;
    c.map_size_m = {bx * 60.0 + 80.0, by * 60.0 + 80.0};
    c.validate();
    for (const char* location : {"boston-seaport", "singapore-hollandvillage"}) {
      c.location = location;
      expect_connected(build_world(c, 21), std::string(location) + " " + std::to_string(bx) + "x" + std::to_string(by));
    }
  }
}

// city.local_streets: only for the organic layout and a rectangle of at least 700 × 400 m.
TEST(OrganicConfig, LocalStreetsNeedTheOrganicLayoutAndRoom) {
  auto rejected_key = [](const std::string& text) {
    try {
      SynthConfig::from_json_text(text, "cfg.json").validate();
    } catch (const ConfigError& e) {
      return e.record();
    }
    return std::string("(accepted)");
  };
  const std::string big = R"("map_size_m": [900, 600], "city": {"origin_m": [50, 50], "blocks_x": 10, "blocks_y": 6, )"
                          R"("block_size_m": 70, "local_streets": true)";
  EXPECT_EQ(rejected_key("{" + big + "}}"), "city.local_streets");  // the grid
  EXPECT_EQ(rejected_key("{" + big + R"(, "layout": "organic"}})"), "(accepted)");
  EXPECT_EQ(rejected_key(R"({"map_size_m": [600, 400], "city": {"layout": "organic", "origin_m": [40, 40], )"
                         R"("blocks_x": 5, "blocks_y": 3, "block_size_m": 100, "local_streets": true}})"),
            "city.local_streets");
}

int junction_areas(const World& w) {
  const nlohmann::json map = nlohmann::json::parse(w.map_json);
  int n = 0;
  for (const auto& seg : map["road_segment"]) n += seg["is_intersection"].get<bool>();
  return n;
}

// With the local streets, sizes from near the smallest accepted (700 × 420 m) to a 3:1 strip and
// both traffic sides build connected worlds with ten more junction areas and more lanes
// than the same plan without them.
TEST(OrganicLaneGraph, LocalStreetsAddJunctionsAndLanesAtEverySize) {
  const std::vector<std::array<int, 2>> blocks = {{10, 6}, {13, 7}, {18, 6}};
  uint64_t seed = 30;
  for (const auto& [bx, by] : blocks) {
    for (const char* location : {"boston-seaport", "singapore-onenorth"}) {
      SynthConfig c = organic_config();
      c.location = location;
      c.city.blocks_x = bx;
      c.city.blocks_y = by;
      c.city.block_size_m = 70.0;
      c.city.ground_resolution_m = 0.2;
      c.map_size_m = {bx * 70.0 + 80.0, by * 70.0 + 80.0};
      const std::string what = std::string(location) + " " + std::to_string(bx) + "x" + std::to_string(by);
      const World plain = build_world(c, ++seed);
      c.city.local_streets = true;
      c.validate();
      const World local = build_world(c, seed);
      expect_connected(local, what);
      EXPECT_EQ(junction_areas(local), junction_areas(plain) + 10) << what;
      size_t lanes_plain = 0, lanes_local = 0;
      for (const LaneInfo& lane : plain.lanes) lanes_plain += !lane.is_connector;
      for (const LaneInfo& lane : local.lanes) lanes_local += !lane.is_connector;
      EXPECT_GE(lanes_local, lanes_plain * 3 / 2) << what;
    }
  }
}

// Buildings stand on bare terrain, clear of roads and sidewalks.
TEST(OrganicWorld, BuildingsStandAwayFromRoads) {
  const World w = build_world(organic_config(), 7);
  ASSERT_FALSE(w.buildings.empty());
  for (const SceneBox& b : w.buildings) {
    for (double fx : {-0.5, 0.0, 0.5}) {
      for (double fy : {-0.5, 0.0, 0.5}) {
        const double x = b.center_m.x() + fx * b.length_m, y = b.center_m.y() + fy * b.width_m;
        EXPECT_EQ(w.ground->material(x, y), GroundMaterial::kTerrain) << x << ", " << y;
      }
    }
  }
  size_t trees = 0;
  for (const ScenePole& p : w.poles) trees += p.cls == SemanticClass::kVegetation;
  EXPECT_GT(trees, 0u);
}

// Intersection areas are the hulls of their arms' ends: oriented polygons, not the grid's
// axis-aligned squares.
TEST(OrganicWorld, IntersectionAreasFollowTheArms) {
  const World w = build_world(organic_config(), 3);
  const nlohmann::json map = nlohmann::json::parse(w.map_json);
  std::map<std::string, std::pair<double, double>> nodes;
  for (const auto& n : map["node"]) nodes[n["token"]] = {n["x"], n["y"]};
  std::map<std::string, std::vector<std::string>> polygons;
  for (const auto& p : map["polygon"]) polygons[p["token"]] = p["exterior_node_tokens"].get<std::vector<std::string>>();
  size_t junctions = 0, skewed_edges = 0, many_sided = 0;
  for (const auto& seg : map["road_segment"]) {
    if (!seg["is_intersection"].get<bool>()) continue;
    ++junctions;
    const std::vector<std::string>& ring = polygons.at(seg["polygon_token"]);
    many_sided += ring.size() > 4;
    for (size_t k = 0; k < ring.size(); ++k) {
      const auto [x0, y0] = nodes.at(ring[k]);
      const auto [x1, y1] = nodes.at(ring[(k + 1) % ring.size()]);
      skewed_edges += std::fabs(x1 - x0) > 0.5 && std::fabs(y1 - y0) > 0.5;
    }
  }
  EXPECT_GE(junctions, 10u);
  EXPECT_GT(skewed_edges, 10u);
  EXPECT_GT(many_sided, 5u);
}

// The traffic planner drives the organic lane graph: ego routes as long as the scene,
// moving vehicles and parked cars around it.
TEST(OrganicWorld, ScenesPlanOnIt) {
  for (const char* location : {"boston-seaport", "singapore-queenstown"}) {
    SynthConfig c = organic_config();
    c.location = location;
    c.city.parking_fraction = 1.0;
    const World w = build_world(c, 5);
    EXPECT_FALSE(w.parking_slots.empty());
    Rng rng(9);
    for (int scene = 0; scene < 8; ++scene) {
      const double duration_s = 20.0;
      const ScenePlan plan = plan_scene(w, duration_s, rng);
      EXPECT_GE(plan.ego.length_m(), plan.ego_start_m + plan.ego_speed_mps * duration_s) << location << " " << scene;
      EXPECT_FALSE(plan.agents.empty());
      // The ego stays on the drivable surface.
      for (double t = 0.0; t <= duration_s; t += 2.0) {
        const geometry::Pose2 p = plan.ego_pose_at(t);
        EXPECT_TRUE(is_drivable_material(w.ground->material(p.x, p.y))) << location << " t " << t;
      }
    }
  }
}

}  // namespace
}  // namespace nsg::synth
