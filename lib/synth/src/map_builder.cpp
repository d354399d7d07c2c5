#include "map_builder.h"

#include <algorithm>

#include "nsg/core/strings.h"
#include "py_json.h"

namespace nsg::synth {

MapBuilder::MapBuilder(Rng rng) : rng_(rng) { drivable_area_token_ = uuid(); }

std::string MapBuilder::uuid() {
  const uint64_t hi = rng_.next_u64(), lo = rng_.next_u64();
  // Version 4 / variant 1 bits, like Python's uuid4().
  const uint64_t h = (hi & 0xffffffffffff0fffULL) | 0x0000000000004000ULL;
  const uint64_t l = (lo & 0x3fffffffffffffffULL) | 0x8000000000000000ULL;
  return strprintf("%08llx-%04llx-%04llx-%04llx-%012llx", static_cast<unsigned long long>(h >> 32),
                   static_cast<unsigned long long>((h >> 16) & 0xffff), static_cast<unsigned long long>(h & 0xffff),
                   static_cast<unsigned long long>(l >> 48), static_cast<unsigned long long>(l & 0xffffffffffffULL));
}

std::string MapBuilder::node(const Eigen::Vector2d& p) {
  const std::string t = uuid();
  node_.push_back(Json{{"token", t}, {"x", p.x()}, {"y", p.y()}});
  return t;
}

std::string MapBuilder::line(const Points& pts) {
  const std::string t = uuid();
  last_line_nodes_.clear();
  for (const auto& p : pts) last_line_nodes_.push_back(node(p));
  line_.push_back(Json{{"token", t}, {"node_tokens", last_line_nodes_}});
  return t;
}

std::string MapBuilder::polygon(const Points& ring) {
  const std::string t = uuid();
  std::vector<std::string> nodes;
  for (const auto& p : ring) nodes.push_back(node(p));
  polygon_.push_back(Json{{"token", t}, {"exterior_node_tokens", nodes}, {"holes", Json::array()}});
  return t;
}

std::string MapBuilder::road_segment(const Points& ring, bool is_intersection) {
  const std::string t = uuid();
  road_segment_.push_back(Json{{"token", t},
                               {"polygon_token", polygon(ring)},
                               {"is_intersection", is_intersection},
                               {"drivable_area_token", drivable_area_token_}});
  return t;
}

std::string MapBuilder::road_block(const Points& ring, const Points& from_edge, const Points& to_edge,
                                   const std::string& road_segment) {
  const std::string t = uuid();
  const std::string poly = polygon(ring);
  const std::string from = line(from_edge), to = line(to_edge);
  road_block_.push_back(Json{{"token", t},
                             {"polygon_token", poly},
                             {"from_edge_line_token", from},
                             {"to_edge_line_token", to},
                             {"road_segment_token", road_segment}});
  return t;
}

MapBuilder::Json MapBuilder::segments(const std::vector<std::string>& nodes, const std::string& type) const {
  Json out = Json::array();
  for (const auto& n : nodes) out.push_back(Json{{"node_token", n}, {"segment_type", type}});
  return out;
}

std::string MapBuilder::lane(const Points& left, const Points& right, const std::string& left_type,
                             const std::string& right_type) {
  const std::string t = uuid();
  // Polygon nodes double as the divider-segment nodes (left boundary, then right reversed).
  const std::string poly = uuid();
  std::vector<std::string> left_nodes, right_nodes;
  for (const auto& p : left) left_nodes.push_back(node(p));
  for (auto it = right.rbegin(); it != right.rend(); ++it) right_nodes.push_back(node(*it));
  std::vector<std::string> ring = left_nodes;
  ring.insert(ring.end(), right_nodes.begin(), right_nodes.end());
  polygon_.push_back(Json{{"token", poly}, {"exterior_node_tokens", ring}, {"holes", Json::array()}});
  std::vector<std::string> right_fwd(right_nodes.rbegin(), right_nodes.rend());
  const std::string from = line({right.front(), left.front()}), to = line({right.back(), left.back()});
  lane_.push_back(Json{{"token", t},
                       {"polygon_token", poly},
                       {"lane_type", "CAR"},
                       {"from_edge_line_token", from},
                       {"to_edge_line_token", to},
                       {"left_lane_divider_segments", segments(left_nodes, left_type)},
                       {"right_lane_divider_segments", segments(right_fwd, right_type)}});
  return t;
}

std::string MapBuilder::lane_connector(const Points& ring) {
  const std::string t = uuid();
  lane_connector_.push_back(Json{{"token", t}, {"polygon_token", polygon(ring)}});
  return t;
}

std::string MapBuilder::ped_crossing(const Points& ring, const std::string& road_segment) {
  const std::string t = uuid();
  ped_crossing_.push_back(Json{{"token", t}, {"polygon_token", polygon(ring)}, {"road_segment_token", road_segment}});
  return t;
}

std::string MapBuilder::walkway(const Points& ring) {
  const std::string t = uuid();
  walkway_.push_back(Json{{"token", t}, {"polygon_token", polygon(ring)}});
  return t;
}

std::string MapBuilder::stop_line(const Points& ring, const std::string& type,
                                  const std::vector<std::string>& ped_crossings,
                                  const std::vector<std::string>& traffic_lights, const std::string& road_block) {
  const std::string t = uuid();
  stop_line_.push_back(Json{{"token", t},
                            {"polygon_token", polygon(ring)},
                            {"stop_line_type", type},
                            {"ped_crossing_tokens", ped_crossings},
                            {"traffic_light_tokens", traffic_lights},
                            {"road_block_token", road_block}});
  return t;
}

std::string MapBuilder::carpark_area(const Points& ring, double orientation_rad, const std::string& road_block) {
  const std::string t = uuid();
  carpark_area_.push_back(Json{{"token", t},
                               {"polygon_token", polygon(ring)},
                               {"orientation", orientation_rad},
                               {"road_block_token", road_block}});
  return t;
}

std::string MapBuilder::road_divider(const Points& pts, const std::string& road_segment) {
  const std::string t = uuid();
  road_divider_.push_back(Json{{"token", t}, {"line_token", line(pts)}, {"road_segment_token", road_segment}});
  return t;
}

std::string MapBuilder::lane_divider(const Points& pts, const std::string& segment_type) {
  const std::string t = uuid();
  const std::string l = line(pts);
  lane_divider_.push_back(
      Json{{"token", t}, {"line_token", l}, {"lane_divider_segments", segments(last_line_nodes_, segment_type)}});
  return t;
}

std::string MapBuilder::traffic_light(const Points& pts, const std::string& from_road_block,
                                      const std::vector<std::string>& to_road_blocks, double yaw_rad) {
  const std::string t = uuid();
  Json items = Json::array();
  const char* colors[] = {"RED", "YELLOW", "GREEN"};
  for (int i = 0; i < 3; ++i) {
    items.push_back(Json{
        {"color", colors[i]},
        {"shape", "CIRCLE"},
        {"rel_pos", Json{{"tx", 0.0}, {"ty", 0.0}, {"tz", 0.632 - 0.3 * i}, {"rx", 0.0}, {"ry", 0.0}, {"rz", 0.0}}},
        {"to_road_block_tokens", to_road_blocks}});
  }
  const std::string l = line(pts);
  traffic_light_.push_back(Json{
      {"token", t},
      {"line_token", l},
      {"traffic_light_type", "VERTICAL"},
      {"from_road_block_token", from_road_block},
      {"items", items},
      {"pose",
       Json{
           {"tx", pts.front().x()}, {"ty", pts.front().y()}, {"tz", 0.0}, {"rx", 0.0}, {"ry", 0.0}, {"rz", yaw_rad}}}});
  return t;
}

void MapBuilder::drivable_area(const std::vector<std::string>& polygon_tokens) {
  drivable_area_.push_back(Json{{"token", drivable_area_token_}, {"polygon_tokens", polygon_tokens}});
}

bool MapBuilder::remove_lane_record(const std::string& token) {
  const auto take = [](Json& records, const std::string& t) -> Json {
    for (auto it = records.begin(); it != records.end(); ++it)
      if ((*it)["token"] == t) {
        Json r = *it;
        records.erase(it);
        return r;
      }
    return nullptr;
  };
  Json record = take(lane_, token);
  if (record.is_null()) record = take(lane_connector_, token);
  if (record.is_null()) return false;
  take(polygon_, record["polygon_token"].get<std::string>());
  return true;
}

bool MapBuilder::retype_lane_divider(const std::string& divider, const std::vector<std::string>& lanes,
                                     const std::string& from, const std::string& to) {
  const auto retype = [&](Json& segments) {
    for (Json& seg : segments)
      if (seg["segment_type"] == from) seg["segment_type"] = to;
  };
  bool found = false;
  for (Json& d : lane_divider_)
    if (d["token"] == divider) {
      retype(d["lane_divider_segments"]);
      found = true;
    }
  for (Json& lane : lane_)
    if (std::find(lanes.begin(), lanes.end(), lane["token"].get<std::string>()) != lanes.end()) {
      retype(lane["left_lane_divider_segments"]);
      retype(lane["right_lane_divider_segments"]);
    }
  return found;
}

std::string MapBuilder::to_json(const std::array<double, 2>& canvas_edge_m,
                                const std::vector<LaneTopology>& lanes) const {
  Json arcline = Json::object(), connectivity = Json::object();
  for (const LaneTopology& lane : lanes) {
    Json paths = Json::array();
    for (const auto& p : lane.paths) {
      paths.push_back(Json{{"start_pose", {p.start_pose.x, p.start_pose.y, p.start_pose.yaw}},
                           {"end_pose", {p.end_pose.x, p.end_pose.y, p.end_pose.yaw}},
                           {"shape", std::string(geometry::arcline_shape_name(p.shape))},
                           {"radius", p.radius_m},
                           {"segment_length", {p.segment_length_m[0], p.segment_length_m[1], p.segment_length_m[2]}}});
    }
    arcline[lane.token] = paths;
    connectivity[lane.token] = Json{{"incoming", lane.incoming}, {"outgoing", lane.outgoing}};
  }
  Json root = Json::object();
  root["version"] = "1.3";
  root["polygon"] = polygon_;
  root["line"] = line_;
  root["node"] = node_;
  root["drivable_area"] = drivable_area_;
  root["road_segment"] = road_segment_;
  root["road_block"] = road_block_;
  root["lane"] = lane_;
  root["ped_crossing"] = ped_crossing_;
  root["walkway"] = walkway_;
  root["stop_line"] = stop_line_;
  root["carpark_area"] = carpark_area_;
  root["road_divider"] = road_divider_;
  root["lane_divider"] = lane_divider_;
  root["traffic_light"] = traffic_light_;
  root["lane_connector"] = lane_connector_;
  root["arcline_path_3"] = arcline;
  root["connectivity"] = connectivity;
  root["canvas_edge"] = {canvas_edge_m[0], canvas_edge_m[1]};
  return py_json_dump(root, PyJsonStyle::kCompact);
}

}  // namespace nsg::synth
