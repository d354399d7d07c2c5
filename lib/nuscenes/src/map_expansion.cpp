// MapExpansion lookups and the devkit's lane discretization (map_api.py discretize_lanes,
// discretize_centerlines, get_arcline_path, get_outgoing/incoming_lane_ids). Loading is in
// map_parse.cpp (the records) and map_resolve.cpp (indexes and references).
#include "nsg/nuscenes/map_expansion.h"

#include <unordered_set>

#include "nsg/core/error.h"

namespace nsg::nuscenes {

std::string_view map_layer_name(MapLayer layer) {
  static constexpr std::array<std::string_view, kMapLayerCount> kNames = {
      "polygon",      "line",         "node",         "drivable_area", "road_segment",
      "road_block",   "lane",         "ped_crossing", "walkway",       "stop_line",
      "carpark_area", "road_divider", "lane_divider", "traffic_light", "lane_connector"};
  return kNames[static_cast<size_t>(layer)];
}

size_t MapExpansion::size(MapLayer layer) const { return token_index_[static_cast<size_t>(layer)].size(); }

std::optional<MapIndex> MapExpansion::find(MapLayer layer, std::string_view token) const {
  const TokenMap& index = token_index_[static_cast<size_t>(layer)];
  const auto it = index.find(token);
  if (it == index.end()) return std::nullopt;
  return it->second;
}

MapIndex MapExpansion::index_of(MapLayer layer, std::string_view token) const {
  if (const auto found = find(layer, token)) return *found;
  throw DataError(file_.string(), std::string(map_layer_name(layer)) + " '" + std::string(token) + "'",
                  "expected a token of the " + std::string(map_layer_name(layer)) + " layer (not found)");
}

std::optional<MapLayer> MapExpansion::centerline_layer(std::string_view token) const {
  if (find(MapLayer::kLane, token)) return MapLayer::kLane;
  if (find(MapLayer::kLaneConnector, token)) return MapLayer::kLaneConnector;
  return std::nullopt;
}

const std::vector<geometry::ArclinePath>* MapExpansion::find_arcline_path(std::string_view token) const {
  const auto it = arcline_index_.find(token);
  return it == arcline_index_.end() ? nullptr : &arcline_paths_[it->second];
}

const std::vector<geometry::ArclinePath>& MapExpansion::get_arcline_path(std::string_view token) const {
  const auto* paths = find_arcline_path(token);
  if (paths == nullptr || paths->empty()) {
    throw DataError(file_.string(), "arcline_path_3 '" + std::string(token) + "'",
                    paths == nullptr ? "expected an arcline path for this lane token (none)"
                                     : "expected a non-empty arcline path list");
  }
  return *paths;
}

const LaneConnectivity* MapExpansion::find_connectivity(std::string_view token) const {
  const auto it = connectivity_index_.find(token);
  return it == connectivity_index_.end() ? nullptr : &connectivity_[it->second];
}

namespace {
[[noreturn]] void missing_connectivity(const std::filesystem::path& file, std::string_view token) {
  throw DataError(file.string(), "connectivity '" + std::string(token) + "'",
                  "expected a connectivity entry for this lane token (none)");
}
}  // namespace

const std::vector<std::string>& MapExpansion::outgoing(std::string_view token) const {
  const LaneConnectivity* c = find_connectivity(token);
  if (c == nullptr) missing_connectivity(file_, token);
  return c->outgoing;
}

const std::vector<std::string>& MapExpansion::incoming(std::string_view token) const {
  const LaneConnectivity* c = find_connectivity(token);
  if (c == nullptr) missing_connectivity(file_, token);
  return c->incoming;
}

std::vector<geometry::Pose2> MapExpansion::discretize_lane(std::string_view token, double resolution_m) const {
  // arcline_path_3.get(token, []): a token without paths has no poses.
  const auto* paths = find_arcline_path(token);
  if (paths == nullptr) return {};
  return geometry::discretize_lane(*paths, resolution_m);
}

std::vector<Centerline> MapExpansion::discretize_lanes(const std::vector<std::string>& tokens,
                                                       double resolution_m) const {
  std::vector<Centerline> out;
  std::unordered_set<std::string_view> done;  // the devkit returns a dict: one entry per token
  for (const std::string& token : tokens) {
    if (!done.insert(token).second) continue;
    Centerline c;
    c.token = token;
    c.layer = centerline_layer(token).value_or(MapLayer::kLane);
    c.poses = discretize_lane(token, resolution_m);
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<Centerline> MapExpansion::discretize_centerlines(double resolution_m) const {
  std::vector<Centerline> out;
  out.reserve(lane_.size() + lane_connector_.size());
  for (const Lane& lane : lane_) {
    out.push_back({lane.token, MapLayer::kLane, discretize_lane(lane.token, resolution_m)});
  }
  for (const LaneConnector& connector : lane_connector_) {
    out.push_back({connector.token, MapLayer::kLaneConnector, discretize_lane(connector.token, resolution_m)});
  }
  return out;
}

}  // namespace nsg::nuscenes
