// Map expansion reader: one simdjson on-demand pass over the file into typed records,
// then the devkit's load-time checks (docs/nuscenes-input.md) on the resolved references.
// Structure problems (not JSON, wrong type, missing key, non-finite number) are
// ParseErrors; consistent-looking but wrong content (old version, dangling reference,
// invalid arcline path) are DataErrors. Every message names the file, the layer and record
// token (or its position while the token is unknown), the key, and what was expected.
// Defects the devkit loads (null tokens, "" links, degenerate geometry) are not errors:
// they are collected into MapExpansion::issues() (map_defects.h).
// Indexing and resolving the records: map_resolve.cpp.
#include <simdjson.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "map_defects.h"
#include "map_expansion_builder.h"
#include "map_json.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/strings.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::nuscenes {
namespace {

using namespace map_detail;  // the JSON readers and record layouts (map_json.h)
using geometry::ArclinePath;

constexpr std::string_view kMinVersion = "1.3";

// ---- nested values --------------------------------------------------------------------

struct HoleRecord {
  MapHole hole;
};
void hole_nodes(od::value& v, Ctx& c, HoleRecord& r) { r.hole.node_tokens = get_token_list(v, c); }
constexpr std::array<Field<HoleRecord>, 1> kHoleFields{{{"node_tokens", &hole_nodes}}};

void polygon_holes(od::value& v, Ctx& c, MapPolygon& r) {
  for_each_element(v, c, "an array of {\"node_tokens\": [...]} objects", [&](od::value& ev, size_t) {
    HoleRecord hole;
    const std::string_view key = c.key;
    read_object(ev, c, kHoleFields, hole);
    c.key = key;
    r.holes.push_back(std::move(hole.hole));
  });
}

constexpr std::array<Field<LaneDividerSegment>, 2> kSegmentFields{{
    {"node_token", &token_field<LaneDividerSegment, &LaneDividerSegment::node_token>},
    {"segment_type", &string_field<LaneDividerSegment, &LaneDividerSegment::segment_type>},
}};

std::vector<LaneDividerSegment> get_segments(od::value& v, Ctx& c) {
  std::vector<LaneDividerSegment> out;
  const std::string_view key = c.key;
  for_each_element(v, c, "an array of {node_token, segment_type} objects", [&](od::value& ev, size_t) {
    LaneDividerSegment segment;
    read_object(ev, c, kSegmentFields, segment);
    c.key = key;
    out.push_back(std::move(segment));
  });
  return out;
}

template <class R, std::vector<LaneDividerSegment> R::*M>
void segments_field(od::value& v, Ctx& c, R& r) {
  r.*M = get_segments(v, c);
}

constexpr std::array<Field<MapPose6>, 6> kPose6Fields{{
    {"tx", &number_field<MapPose6, &MapPose6::tx>},
    {"ty", &number_field<MapPose6, &MapPose6::ty>},
    {"tz", &number_field<MapPose6, &MapPose6::tz>},
    {"rx", &number_field<MapPose6, &MapPose6::rx>},
    {"ry", &number_field<MapPose6, &MapPose6::ry>},
    {"rz", &number_field<MapPose6, &MapPose6::rz>},
}};

template <class R, MapPose6 R::*M>
void pose6_field(od::value& v, Ctx& c, R& r) {
  const std::string_view key = c.key;
  read_object(v, c, kPose6Fields, r.*M);
  c.key = key;
}

constexpr std::array<Field<TrafficLightItem>, 4> kItemFields{{
    {"color", &string_field<TrafficLightItem, &TrafficLightItem::color>},
    {"shape", &string_field<TrafficLightItem, &TrafficLightItem::shape>},
    {"rel_pos", &pose6_field<TrafficLightItem, &TrafficLightItem::rel_pos>},
    {"to_road_block_tokens", &token_list_field<TrafficLightItem, &TrafficLightItem::to_road_block_tokens>},
}};

void traffic_light_items(od::value& v, Ctx& c, TrafficLight& r) {
  const std::string_view key = c.key;
  for_each_element(v, c, "an array of traffic light items", [&](od::value& ev, size_t) {
    TrafficLightItem item;
    read_object(ev, c, kItemFields, item);
    c.key = key;
    r.items.push_back(std::move(item));
  });
}

// ---- layer layouts --------------------------------------------------------------------

void node_x(od::value& v, Ctx& c, MapNode& r) { r.x_m = get_number(v, c); }
void node_y(od::value& v, Ctx& c, MapNode& r) { r.y_m = get_number(v, c); }
constexpr std::array<Field<MapNode>, 2> kNodeFields{{{"x", &node_x}, {"y", &node_y}}};

constexpr std::array<Field<MapLine>, 1> kLineFields{
    {{"node_tokens", &token_list_field<MapLine, &MapLine::node_tokens>}}};

constexpr std::array<Field<MapPolygon>, 2> kPolygonFields{{
    {"exterior_node_tokens", &token_list_field<MapPolygon, &MapPolygon::exterior_node_tokens>},
    {"holes", &polygon_holes},
}};

constexpr std::array<Field<DrivableArea>, 1> kDrivableAreaFields{
    {{"polygon_tokens", &token_list_field<DrivableArea, &DrivableArea::polygon_tokens>}}};

constexpr std::array<Field<RoadSegment>, 3> kRoadSegmentFields{{
    {"polygon_token", &token_field<RoadSegment, &RoadSegment::polygon_token>},
    {"is_intersection", &bool_field<RoadSegment, &RoadSegment::is_intersection>, false},
    {"drivable_area_token", &token_field<RoadSegment, &RoadSegment::drivable_area_token>, false},
}};

constexpr std::array<Field<RoadBlock>, 4> kRoadBlockFields{{
    {"polygon_token", &token_field<RoadBlock, &RoadBlock::polygon_token>},
    {"from_edge_line_token", &token_field<RoadBlock, &RoadBlock::from_edge_line_token>, false},
    {"to_edge_line_token", &token_field<RoadBlock, &RoadBlock::to_edge_line_token>, false},
    {"road_segment_token", &token_field<RoadBlock, &RoadBlock::road_segment_token>, false},
}};

constexpr std::array<Field<Lane>, 6> kLaneFields{{
    {"polygon_token", &token_field<Lane, &Lane::polygon_token>},
    {"lane_type", &string_field<Lane, &Lane::lane_type>, false},
    {"from_edge_line_token", &token_field<Lane, &Lane::from_edge_line_token>, false},
    {"to_edge_line_token", &token_field<Lane, &Lane::to_edge_line_token>, false},
    {"left_lane_divider_segments", &segments_field<Lane, &Lane::left_lane_divider_segments>},
    {"right_lane_divider_segments", &segments_field<Lane, &Lane::right_lane_divider_segments>},
}};

constexpr std::array<Field<LaneConnector>, 1> kLaneConnectorFields{
    {{"polygon_token", &token_field<LaneConnector, &LaneConnector::polygon_token>, false}}};

constexpr std::array<Field<PedCrossing>, 2> kPedCrossingFields{{
    {"polygon_token", &token_field<PedCrossing, &PedCrossing::polygon_token>},
    {"road_segment_token", &token_field<PedCrossing, &PedCrossing::road_segment_token>, false},
}};

constexpr std::array<Field<Walkway>, 1> kWalkwayFields{
    {{"polygon_token", &token_field<Walkway, &Walkway::polygon_token>}}};

constexpr std::array<Field<StopLine>, 5> kStopLineFields{{
    {"polygon_token", &token_field<StopLine, &StopLine::polygon_token>},
    {"stop_line_type", &string_field<StopLine, &StopLine::stop_line_type>},
    {"ped_crossing_tokens", &token_list_field<StopLine, &StopLine::ped_crossing_tokens>},
    {"traffic_light_tokens", &token_list_field<StopLine, &StopLine::traffic_light_tokens>},
    {"road_block_token", &token_field<StopLine, &StopLine::road_block_token>, false},
}};

constexpr std::array<Field<CarparkArea>, 3> kCarparkAreaFields{{
    {"polygon_token", &token_field<CarparkArea, &CarparkArea::polygon_token>},
    {"orientation", &number_field<CarparkArea, &CarparkArea::orientation_rad>, false},
    {"road_block_token", &token_field<CarparkArea, &CarparkArea::road_block_token>, false},
}};

constexpr std::array<Field<RoadDivider>, 2> kRoadDividerFields{{
    {"line_token", &token_field<RoadDivider, &RoadDivider::line_token>},
    {"road_segment_token", &token_field<RoadDivider, &RoadDivider::road_segment_token>, false},
}};

constexpr std::array<Field<LaneDivider>, 2> kLaneDividerFields{{
    {"line_token", &token_field<LaneDivider, &LaneDivider::line_token>},
    {"lane_divider_segments", &segments_field<LaneDivider, &LaneDivider::lane_divider_segments>, false},
}};

constexpr std::array<Field<TrafficLight>, 5> kTrafficLightFields{{
    {"line_token", &token_field<TrafficLight, &TrafficLight::line_token>},
    {"traffic_light_type", &string_field<TrafficLight, &TrafficLight::traffic_light_type>, false},
    {"from_road_block_token", &token_field<TrafficLight, &TrafficLight::from_road_block_token>, false},
    {"items", &traffic_light_items, false},
    {"pose", &pose6_field<TrafficLight, &TrafficLight::pose>, false},
}};

// ---- arcline paths and connectivity ---------------------------------------------------

struct PathRecord {
  ArclinePath path;
  std::string shape;
  std::array<double, 3> start{}, end{}, segments{};
  double radius = 0.0;
};
void path_start(od::value& v, Ctx& c, PathRecord& r) { r.start = get_numbers<3>(v, c); }
void path_end(od::value& v, Ctx& c, PathRecord& r) { r.end = get_numbers<3>(v, c); }
void path_segments(od::value& v, Ctx& c, PathRecord& r) { r.segments = get_numbers<3>(v, c); }
void path_radius(od::value& v, Ctx& c, PathRecord& r) { r.radius = get_number(v, c); }
constexpr std::array<Field<PathRecord>, 5> kPathFields{{
    {"start_pose", &path_start},
    {"end_pose", &path_end, false},  // never read by the devkit
    {"shape", &string_field<PathRecord, &PathRecord::shape>},
    {"radius", &path_radius},
    {"segment_length", &path_segments},
}};

ArclinePath read_arcline_path(od::value& v, Ctx& c) {
  PathRecord r;
  read_object(v, c, kPathFields, r);
  ArclinePath& p = r.path;
  if (!geometry::parse_arcline_shape(r.shape, &p.shape)) {
    c.key = "shape";
    c.data_fail("one of LSL, LSR, RSL, RSR, LRL, RLR, got \"" + r.shape + "\"");
  }
  if (!(r.radius > 0.0)) {
    c.key = "radius";
    c.data_fail("a radius > 0 m, got " + format_double(r.radius));
  }
  for (double s : r.segments) {
    if (s < 0.0) {
      c.key = "segment_length";
      c.data_fail("segment lengths >= 0 m, got " + format_double(s));
    }
  }
  p.start_pose = {r.start[0], r.start[1], r.start[2]};
  p.end_pose = {r.end[0], r.end[1], r.end[2]};
  p.radius_m = r.radius;
  p.segment_length_m = r.segments;
  c.key = {};
  return p;
}

constexpr std::array<Field<LaneConnectivity>, 2> kConnectivityFields{{
    {"incoming", &token_list_field<LaneConnectivity, &LaneConnectivity::incoming>},
    {"outgoing", &token_list_field<LaneConnectivity, &LaneConnectivity::outgoing>},
}};

}  // namespace

namespace {

struct TopKey {
  std::string_view name;
  bool required;
};
// Top-level keys of a v1.3 file; all but "version" must be present.
constexpr std::array<TopKey, 19> kTopKeys{{
    {"version", false},       {"polygon", true},      {"line", true},          {"node", true},
    {"drivable_area", true},  {"road_segment", true}, {"road_block", true},    {"lane", true},
    {"ped_crossing", true},   {"walkway", true},      {"stop_line", true},     {"carpark_area", true},
    {"road_divider", true},   {"lane_divider", true}, {"traffic_light", true}, {"lane_connector", true},
    {"arcline_path_3", true}, {"connectivity", true}, {"canvas_edge", true},
}};

}  // namespace

void MapExpansionBuilder::check_version(const std::string& version) const {
  // The devkit compares version strings lexicographically: "1.10" < "1.3" is rejected too.
  if (version < kMinVersion) {
    throw DataError(c_.file, "key \"version\"",
                    "expected a map expansion version >= \"1.3\" (string comparison, like the "
                    "devkit), got \"" +
                        version + "\"; download the current map expansion");
  }
}

template <class R, size_t N>
void MapExpansionBuilder::read_layer(od::value& v, std::string_view layer, const std::array<Field<R>, N>& spec,
                                     std::vector<R>& out) {
  c_.layer = layer;
  for_each_element(v, c_, "an array of records", [&](od::value& ev, size_t i) {
    c_.index = i;
    c_.token.clear();
    R record;
    read_record(ev, c_, spec, record);
    out.push_back(std::move(record));
  });
  c_.layer = {};
  c_.token.clear();
}

void MapExpansionBuilder::read_arclines(od::value& v) {
  od::object object;
  c_.key = "arcline_path_3";
  if (auto ec = v.get_object().get(object)) c_.parse_fail("an object keyed by lane token", ec);
  c_.key = {};
  c_.layer = "arcline_path_3";
  for (auto field_result : object) {
    od::field field;
    if (auto ec = std::move(field_result).get(field)) c_.parse_fail("a key/value pair", ec);
    std::string_view token;
    if (auto ec = field.unescaped_key().get(token)) c_.parse_fail("a string key", ec);
    c_.token = std::string(token);
    c_.in_list = false;
    if (!m_.arcline_index_.emplace(c_.token, m_.arcline_tokens_.size()).second) {
      c_.data_fail("each lane token once (it repeats)");
    }
    od::value& value = field.value();
    std::vector<ArclinePath> paths;
    for_each_element(value, c_, "an array of arcline paths", [&](od::value& ev, size_t i) {
      c_.index = i;
      c_.in_list = true;
      paths.push_back(read_arcline_path(ev, c_));
    });
    m_.arcline_tokens_.push_back(c_.token);
    m_.arcline_paths_.push_back(std::move(paths));
  }
  c_.layer = {};
  c_.token.clear();
  c_.in_list = false;
}

void MapExpansionBuilder::read_connectivity(od::value& v) {
  od::object object;
  c_.key = "connectivity";
  if (auto ec = v.get_object().get(object)) c_.parse_fail("an object keyed by lane token", ec);
  c_.key = {};
  c_.layer = "connectivity";
  for (auto field_result : object) {
    od::field field;
    if (auto ec = std::move(field_result).get(field)) c_.parse_fail("a key/value pair", ec);
    std::string_view token;
    if (auto ec = field.unescaped_key().get(token)) c_.parse_fail("a string key", ec);
    c_.token = std::string(token);
    if (!m_.connectivity_index_.emplace(c_.token, m_.connectivity_tokens_.size()).second) {
      c_.data_fail("each lane token once (it repeats)");
    }
    od::value& value = field.value();
    LaneConnectivity record;
    read_object(value, c_, kConnectivityFields, record);
    m_.connectivity_tokens_.push_back(c_.token);
    m_.connectivity_.push_back(std::move(record));
  }
  c_.layer = {};
  c_.token.clear();
}

void MapExpansionBuilder::parse_top_level(od::object& top) {
  std::uint32_t seen = 0;
  for (auto field_result : top) {
    od::field field;
    c_.key = {};
    if (auto ec = std::move(field_result).get(field)) c_.parse_fail("a key/value pair", ec);
    std::string_view key;
    if (auto ec = field.unescaped_key().get(key)) c_.parse_fail("a string key", ec);
    size_t k = 0;
    while (k < kTopKeys.size() && kTopKeys[k].name != key) ++k;
    od::value& value = field.value();
    if (k == kTopKeys.size()) continue;  // unknown top-level keys are ignored
    c_.key = kTopKeys[k].name;
    if (seen & (1u << k)) c_.parse_fail("each top-level key once (it repeats)");
    seen |= 1u << k;
    c_.key = {};
    if (key == "version") {
      continue;  // read and checked before this pass
    } else if (key == "polygon") {
      read_layer(value, key, kPolygonFields, m_.polygon_);
    } else if (key == "line") {
      read_layer(value, key, kLineFields, m_.line_);
    } else if (key == "node") {
      read_layer(value, key, kNodeFields, m_.node_);
    } else if (key == "drivable_area") {
      read_layer(value, key, kDrivableAreaFields, m_.drivable_area_);
    } else if (key == "road_segment") {
      read_layer(value, key, kRoadSegmentFields, m_.road_segment_);
    } else if (key == "road_block") {
      read_layer(value, key, kRoadBlockFields, m_.road_block_);
    } else if (key == "lane") {
      read_layer(value, key, kLaneFields, m_.lane_);
    } else if (key == "ped_crossing") {
      read_layer(value, key, kPedCrossingFields, m_.ped_crossing_);
    } else if (key == "walkway") {
      read_layer(value, key, kWalkwayFields, m_.walkway_);
    } else if (key == "stop_line") {
      read_layer(value, key, kStopLineFields, m_.stop_line_);
    } else if (key == "carpark_area") {
      read_layer(value, key, kCarparkAreaFields, m_.carpark_area_);
    } else if (key == "road_divider") {
      read_layer(value, key, kRoadDividerFields, m_.road_divider_);
    } else if (key == "lane_divider") {
      read_layer(value, key, kLaneDividerFields, m_.lane_divider_);
    } else if (key == "traffic_light") {
      read_layer(value, key, kTrafficLightFields, m_.traffic_light_);
    } else if (key == "lane_connector") {
      read_layer(value, key, kLaneConnectorFields, m_.lane_connector_);
    } else if (key == "arcline_path_3") {
      read_arclines(value);
    } else if (key == "connectivity") {
      read_connectivity(value);
    } else if (key == "canvas_edge") {
      c_.key = "canvas_edge";
      m_.canvas_edge_m_ = get_numbers<2>(value, c_);
      if (!(m_.canvas_edge_m_[0] > 0.0 && m_.canvas_edge_m_[1] > 0.0)) {
        c_.data_fail("[width, height] > 0 m");
      }
      c_.key = {};
    }
  }
  for (size_t k = 0; k < kTopKeys.size(); ++k) {
    if (kTopKeys[k].required && !(seen & (1u << k))) {
      c_.key = kTopKeys[k].name;
      c_.parse_fail("this required top-level key (missing)");
    }
  }
}

void MapExpansionBuilder::parse(const std::filesystem::path& path) {
  require_file(path, "map expansion");
  simdjson::padded_string json;
  if (auto ec = simdjson::padded_string::load(path.string()).get(json)) {
    throw IoError(c_.file, "", std::string("cannot read: ") + simdjson::error_message(ec));
  }
  od::parser parser;
  od::document doc;
  if (auto ec = parser.iterate(json).get(doc)) c_.parse_fail("a JSON document", ec);
  od::object top;
  if (auto ec = doc.get_object().get(top)) {
    if (ec == simdjson::INCOMPLETE_ARRAY_OR_OBJECT) fail_truncated(json);
    c_.parse_fail("a JSON object at the top level", ec);
  }

  // Version first (like the devkit): an outdated map is rejected before its layers are read.
  od::value version_value;
  c_.key = "version";
  const auto vec = top.find_field_unordered("version").get(version_value);
  if (vec == simdjson::NO_SUCH_FIELD) {
    m_.version_ = "1.0";  // the devkit's default for maps without a version
  } else if (vec) {
    c_.parse_fail("a JSON object", vec);
  } else {
    m_.version_ = std::string(get_string(version_value, c_));
  }
  c_.key = {};
  check_version(m_.version_);
  bool is_empty = false;
  if (auto ec = top.reset().get(is_empty)) c_.parse_fail("a JSON object at the top level", ec);

  parse_top_level(top);
  // Anything after the top-level object is an error (e.g. two documents concatenated).
  const char* rest = nullptr;
  if (doc.current_location().get(rest) == simdjson::SUCCESS) {
    c_.parse_fail("the end of the file after the top-level object");
  }
}

// simdjson checks the bracket balance before the first value is read, so a truncated file
// is reported with the last record token seen before the end: where to look for the damage.
void MapExpansionBuilder::fail_truncated(std::string_view json) const {
  constexpr std::string_view kTokenKey = "\"token\"";
  std::string last_token;
  const size_t key = json.rfind(kTokenKey);
  if (key != std::string_view::npos) {
    const size_t open = json.find('"', key + kTokenKey.size());
    const size_t close = open == std::string_view::npos ? open : json.find('"', open + 1);
    if (close != std::string_view::npos && close - open <= 80) {
      last_token = std::string(json.substr(open + 1, close - open - 1));
    }
  }
  const std::string where =
      last_token.empty() ? std::string() : " (the last record token before the end is '" + last_token + "')";
  throw ParseError(c_.file, last_token.empty() ? "" : "record '" + last_token + "'",
                   strprintf("expected a complete JSON document: the file ends early after %zu "
                             "bytes, inside an object or array%s",
                             json.size(), where.c_str()));
}

}  // namespace nsg::nuscenes
