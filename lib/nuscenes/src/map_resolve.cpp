// Map expansion reader, second pass: the token index of every layer, then the devkit's
// load-time reference checks (its _make_shortcuts and _get_stop_line_cue) on the records
// map_parse.cpp read. A dangling reference is a DataError naming the file, the layer and
// record token, the key and the missing token; a null link the devkit tolerates is a defect.
#include <algorithm>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "map_defects.h"
#include "map_expansion_builder.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/geometry/georef.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::nuscenes {

using namespace map_detail;  // record_label and check_geometry (map_defects.h)

template <class R>
void MapExpansionBuilder::index_layer(MapLayer layer, const std::vector<R>& records) {
  MapExpansion::TokenMap& index = m_.token_index_[static_cast<size_t>(layer)];
  index.reserve(records.size());
  for (size_t i = 0; i < records.size(); ++i) {
    const auto [it, inserted] = index.emplace(records[i].token, static_cast<MapIndex>(i));
    if (!inserted) {
      throw DataError(c_.file, std::string(map_layer_name(layer)) + " '" + records[i].token + "'",
                      strprintf("expected unique tokens in the layer (records #%u and #%zu share it)", it->second, i));
    }
  }
}

void MapExpansionBuilder::index_layers() {
  index_layer(MapLayer::kPolygon, m_.polygon_);
  index_layer(MapLayer::kLine, m_.line_);
  index_layer(MapLayer::kNode, m_.node_);
  index_layer(MapLayer::kDrivableArea, m_.drivable_area_);
  index_layer(MapLayer::kRoadSegment, m_.road_segment_);
  index_layer(MapLayer::kRoadBlock, m_.road_block_);
  index_layer(MapLayer::kLane, m_.lane_);
  index_layer(MapLayer::kPedCrossing, m_.ped_crossing_);
  index_layer(MapLayer::kWalkway, m_.walkway_);
  index_layer(MapLayer::kStopLine, m_.stop_line_);
  index_layer(MapLayer::kCarparkArea, m_.carpark_area_);
  index_layer(MapLayer::kRoadDivider, m_.road_divider_);
  index_layer(MapLayer::kLaneDivider, m_.lane_divider_);
  index_layer(MapLayer::kTrafficLight, m_.traffic_light_);
  index_layer(MapLayer::kLaneConnector, m_.lane_connector_);
}

MapIndex MapExpansionBuilder::resolve(MapLayer target, std::string_view token, MapLayer from,
                                      const std::string& from_token, std::string_view field) const {
  if (const auto found = m_.find(target, token)) return *found;
  // A null link reads as "": the devkit finds the record whose own token is null, if any.
  // (append, not "'" + std::string(token): GCC 12 reports a false -Wrestrict on that here.)
  const std::string got =
      token.empty() ? "null or \"\", and no " + std::string(map_layer_name(target)) + " record has a null token"
                    : std::string("'").append(token).append("'");
  throw DataError(c_.file, std::string(map_layer_name(from)) + " '" + from_token + "'",
                  "key \"" + std::string(field) + "\": expected an existing " + std::string(map_layer_name(target)) +
                      " token, got " + got + " (dangling reference)");
}

void MapExpansionBuilder::resolve_references() {
  using L = MapLayer;
  const auto nodes_of = [&](const std::vector<std::string>& tokens, L from, const std::string& tok,
                            std::string_view field) {
    std::vector<MapIndex> out;
    out.reserve(tokens.size());
    for (const std::string& t : tokens) out.push_back(resolve(L::kNode, t, from, tok, field));
    return out;
  };
  for (MapLine& r : m_.line_) r.nodes = nodes_of(r.node_tokens, L::kLine, r.token, "node_tokens");
  for (MapPolygon& r : m_.polygon_) {
    r.exterior_nodes = nodes_of(r.exterior_node_tokens, L::kPolygon, r.token, "exterior_node_tokens");
    for (MapHole& h : r.holes) h.nodes = nodes_of(h.node_tokens, L::kPolygon, r.token, "holes");
  }
  resolve_drivable_areas();
  // The devkit's _make_shortcuts: polygon of every polygon layer, line of every line layer.
  const auto polygon_of = [&](auto& records, L from) {
    for (auto& r : records) r.polygon = resolve(L::kPolygon, r.polygon_token, from, r.token, "polygon_token");
  };
  polygon_of(m_.road_segment_, L::kRoadSegment);
  polygon_of(m_.road_block_, L::kRoadBlock);
  polygon_of(m_.lane_, L::kLane);
  polygon_of(m_.ped_crossing_, L::kPedCrossing);
  polygon_of(m_.walkway_, L::kWalkway);
  polygon_of(m_.stop_line_, L::kStopLine);
  polygon_of(m_.carpark_area_, L::kCarparkArea);
  // Connector polygons are placeholders the devkit never resolves: resolved if present only.
  for (LaneConnector& r : m_.lane_connector_) {
    r.polygon = m_.find(L::kPolygon, r.polygon_token).value_or(kNoMapIndex);
  }
  const auto line_of = [&](auto& records, L from) {
    for (auto& r : records) r.line = resolve(L::kLine, r.line_token, from, r.token, "line_token");
  };
  line_of(m_.road_divider_, L::kRoadDivider);
  line_of(m_.lane_divider_, L::kLaneDivider);
  line_of(m_.traffic_light_, L::kTrafficLight);
  const auto segment_nodes = [&](std::vector<LaneDividerSegment>& segments, L from, const std::string& tok,
                                 std::string_view field) {
    for (LaneDividerSegment& s : segments) s.node = resolve(L::kNode, s.node_token, from, tok, field);
  };
  for (Lane& r : m_.lane_) {
    segment_nodes(r.left_lane_divider_segments, L::kLane, r.token, "left_lane_divider_segments");
    segment_nodes(r.right_lane_divider_segments, L::kLane, r.token, "right_lane_divider_segments");
  }
  for (LaneDivider& r : m_.lane_divider_) {
    segment_nodes(r.lane_divider_segments, L::kLaneDivider, r.token, "lane_divider_segments");
  }
  // The devkit's _get_stop_line_cue: cue records must exist for these types.
  for (const StopLine& r : m_.stop_line_) {
    if (r.stop_line_type == "PED_CROSSING" || r.stop_line_type == "TURN_STOP") {
      for (const std::string& t : r.ped_crossing_tokens) {
        resolve(L::kPedCrossing, t, L::kStopLine, r.token, "ped_crossing_tokens");
      }
    } else if (r.stop_line_type == "TRAFFIC_LIGHT") {
      for (const std::string& t : r.traffic_light_tokens) {
        resolve(L::kTrafficLight, t, L::kStopLine, r.token, "traffic_light_tokens");
      }
    }
  }
}

// The devkit never resolves drivable_area polygons at load (it skips the layer in
// _make_shortcuts), so a null entry that finds no null-token polygon is left out of
// `polygons` with a warning; a dangling non-null token stays an error, as it would fail
// the devkit's first use of the record.
void MapExpansionBuilder::resolve_drivable_areas() {
  for (size_t i = 0; i < m_.drivable_area_.size(); ++i) {
    DrivableArea& r = m_.drivable_area_[i];
    for (const std::string& t : r.polygon_tokens) {
      if (t.empty() && !m_.find(MapLayer::kPolygon, t)) {
        defects_.add(Severity::kWarning, "map.unresolved_null", "drivable_area", "polygon_tokens",
                     record_label(r.token, i),
                     "holds null or \"\" but no polygon has a null token; the entry is left out");
        continue;
      }
      r.polygons.push_back(resolve(MapLayer::kPolygon, t, MapLayer::kDrivableArea, r.token, "polygon_tokens"));
    }
  }
}

MapExpansion MapExpansionBuilder::load(const std::filesystem::path& path) {
  MapExpansion map;
  map.file_ = path;
  map.location_ = path.stem().string();
  MapExpansionBuilder builder(map, path);
  builder.parse(path);
  builder.index_layers();
  builder.resolve_references();
  check_geometry(map, builder.defects_);
  map.issues_ = builder.defects_.issues();
  return map;
}

MapExpansion load_map_expansion_file(const std::filesystem::path& path) { return MapExpansionBuilder::load(path); }

namespace {

// The locations whose map expansion this release holds, for messages: "boston-seaport, …".
std::string locations_here(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

}  // namespace

MapExpansion load_map_expansion(const std::filesystem::path& dataroot, std::string_view location) {
  const std::filesystem::path folder = dataroot / "maps" / "expansion";
  const std::filesystem::path file = folder / (std::string(location) + ".json");
  try {
    (void)geometry::location_info(location);  // ConfigError unless one of the four names
  } catch (const ConfigError&) {
    throw ConfigError("", "location '" + std::string(location) + "'",
                      "unknown: not a nuScenes location (this release has: " + locations_here(folder) + ")");
  }
  NSG_CHECK(std::filesystem::exists(file), IoError, file.string(), "location '" + std::string(location) + "'",
            "no map expansion of this location in the release (it has: " + locations_here(folder) + ")");
  return MapExpansionBuilder::load(file);
}

}  // namespace nsg::nuscenes
