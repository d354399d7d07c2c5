#pragma once
// Every map-expansion defect that docs/nuscenes-input.md lists for the real v1.3 maps,
// added as JSON edits to a clean map (tests/data/map/small-map.json or a synthetic one), so
// that the tests know exactly what was added: null tokens, "" links, dangling connectivity,
// an isolated lane → lane → connector → connector chain with a 3 mm gap and a 4.4e-5 m
// arcline segment, a zero-node line, an empty hole, a self-intersecting polygon, 300 extra
// drivable areas, an empty carpark_area layer and traffic lights posed at zero.
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

#include "test_support.h"

namespace nsg::test {

using OJson = nlohmann::ordered_json;

// What add_real_map_defects adds (names and counts the tests assert on).
struct RealMapDefects {
  static constexpr const char* kIslandA = "island-a";    // lane
  static constexpr const char* kIslandB = "island-b";    // lane, starts 3 mm after A ends
  static constexpr const char* kIslandC = "island-c";    // connector, 4.4e-5 m + 5 m paths
  static constexpr const char* kIslandD = "island-d";    // connector after a connector
  static constexpr const char* kGhostOut = "ghost-out";  // dangling outgoing token
  static constexpr const char* kGhostIn = "ghost-in";    // dangling incoming token
  static constexpr size_t kExtraDrivableAreas = 300;
  static constexpr double kGapM = 0.003;
  static constexpr double kTinySegmentM = 4.4e-5;
  // The island chain, resampled at ≤ 2 m: 6 m, 6 m, 5.000044 m and 5 m → 4 nodes each,
  // joined end to start (16 − 3 nodes, 12 edges); joining B's start onto A's end 3 mm away
  // stretches B's first edge to 2.003 m, which gets one more node: 14 nodes, 13 edges.
  static constexpr size_t kIslandNodes = 14;
  static constexpr size_t kIslandEdges = 13;
};

inline OJson straight_path(double x, double y, double yaw, double length_m) {
  return OJson{{"start_pose", {x, y, yaw}},
               {"end_pose", {x + length_m * std::cos(yaw), y + length_m * std::sin(yaw), yaw}},
               {"shape", "LSL"},
               {"radius", 999.999},
               {"segment_length", {0.0, length_m, 0.0}}};
}

inline void add_node(OJson& m, const std::string& token, double x, double y) {
  m["node"].push_back(OJson{{"token", token}, {"x", x}, {"y", y}});
}

// A lane or connector of the island chain; its polygon token is null (as in queenstown).
inline void add_island_lane(OJson& m, const std::string& token, bool connector, OJson paths, OJson incoming,
                            OJson outgoing) {
  if (connector) {
    m["lane_connector"].push_back(OJson{{"token", token}, {"polygon_token", nullptr}});
  } else {
    m["lane"].push_back(OJson{{"token", token},
                              {"polygon_token", nullptr},
                              {"lane_type", "CAR"},
                              {"from_edge_line_token", ""},
                              {"to_edge_line_token", ""},
                              {"left_lane_divider_segments", OJson::array()},
                              {"right_lane_divider_segments", OJson::array()}});
  }
  m["arcline_path_3"][token] = std::move(paths);
  m["connectivity"][token] = OJson{{"incoming", std::move(incoming)}, {"outgoing", std::move(outgoing)}};
}

// The polygons: the map-sized one with a null token and an empty hole (queenstown), a bow
// tie (self-intersecting, #694), and two valid rings the self-intersection check must pass:
// a concave U and a square with a node repeated in a row.
inline void add_defect_polygons(OJson& m) {
  const double w = m["canvas_edge"][0].get<double>(), h = m["canvas_edge"][1].get<double>();
  add_node(m, "corner-0", 0, 0);
  add_node(m, "corner-1", w, 0);
  add_node(m, "corner-2", w, h);
  add_node(m, "corner-3", 0, h);
  m["polygon"].push_back(OJson{{"token", nullptr},
                               {"exterior_node_tokens", {"corner-0", "corner-1", "corner-2", "corner-3"}},
                               {"holes", {OJson{{"node_tokens", OJson::array()}}}}});
  const double xy[][2] = {{1, 1}, {5, 5}, {5, 1}, {1, 5}};
  for (int i = 0; i < 4; ++i) add_node(m, "bow-" + std::to_string(i), xy[i][0], xy[i][1]);
  m["polygon"].push_back(OJson{
      {"token", "bowtie"}, {"exterior_node_tokens", {"bow-0", "bow-1", "bow-2", "bow-3"}}, {"holes", OJson::array()}});
  m["walkway"].push_back(OJson{{"token", "ww-bowtie"}, {"polygon_token", "bowtie"}});
  const double u[][2] = {{0, 0}, {6, 0}, {6, 6}, {4, 6}, {4, 2}, {2, 2}, {2, 6}, {0, 6}};
  OJson ring = OJson::array();
  for (int i = 0; i < 8; ++i) {
    add_node(m, "u-" + std::to_string(i), u[i][0] + 10, u[i][1] + 10);
    ring.push_back("u-" + std::to_string(i));
  }
  m["polygon"].push_back(OJson{{"token", "u-shape"}, {"exterior_node_tokens", ring}, {"holes", OJson::array()}});
  m["polygon"].push_back(OJson{{"token", "square-repeat"},
                               {"exterior_node_tokens", {"u-0", "u-1", "u-1", "u-2", "u-7"}},
                               {"holes", OJson::array()}});
}

// The isolated chain A → B → C → D near the north-east corner of the canvas.
inline void add_island_chain(OJson& m) {
  using D = RealMapDefects;
  const double x0 = m["canvas_edge"][0].get<double>() * 0.9 - 30.0;
  const double y0 = m["canvas_edge"][1].get<double>() * 0.9;
  const double b0 = x0 + 6.0 + D::kGapM, c0 = b0 + 6.0, c1 = c0 + D::kTinySegmentM;
  add_island_lane(m, D::kIslandA, false, {straight_path(x0, y0, 0, 6.0)}, OJson::array(), {D::kIslandB});
  add_island_lane(m, D::kIslandB, false, {straight_path(b0, y0, 0, 6.0)}, {D::kIslandA}, {D::kIslandC});
  add_island_lane(m, D::kIslandC, true, {straight_path(c0, y0, 0, D::kTinySegmentM), straight_path(c1, y0, 0, 5.0)},
                  {D::kIslandB}, {D::kIslandD});
  add_island_lane(m, D::kIslandD, true, {straight_path(c1 + 5.0, y0, 0, 5.0)}, {D::kIslandC}, OJson::array());
}

inline void add_real_map_defects(OJson& m) {
  add_defect_polygons(m);
  for (OJson& r : m["road_block"]) r["polygon_token"] = nullptr;
  m["drivable_area"][0]["polygon_tokens"].push_back(nullptr);
  for (size_t i = 0; i < RealMapDefects::kExtraDrivableAreas; ++i) {
    m["drivable_area"].push_back(OJson{{"token", "da-extra-" + std::to_string(i)}, {"polygon_tokens", {nullptr}}});
  }
  for (OJson& r : m["ped_crossing"]) r["road_segment_token"] = "";
  for (OJson& r : m["stop_line"]) r["road_block_token"] = "";
  for (OJson& r : m["road_segment"]) r["drivable_area_token"] = "";
  m["carpark_area"] = OJson::array();
  for (OJson& r : m["traffic_light"]) {
    r["pose"] = OJson{{"tx", 0.0}, {"ty", 0.0}, {"tz", 2.5}, {"rx", 0.0}, {"ry", 0.0}, {"rz", 0.0}};
  }
  m["line"].push_back(OJson{{"token", "line-zero"}, {"node_tokens", OJson::array()}});
  // Dangling connectivity on the first lane of the file (a real, connected one).
  OJson& first = m["connectivity"][m["lane"][0]["token"].get<std::string>()];
  first["outgoing"].push_back(RealMapDefects::kGhostOut);
  first["incoming"].push_back(RealMapDefects::kGhostIn);
  add_island_chain(m);
}

inline OJson read_json_file(const std::filesystem::path& path) { return OJson::parse(read_text(path)); }
inline void write_json_file(const std::filesystem::path& path, const OJson& j) { write_text(path, j.dump(1)); }

}  // namespace nsg::test
