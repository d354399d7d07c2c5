#pragma once
// The nuScenes map expansion v1.3 (`maps/expansion/<location>.json`, docs/nuscenes-input.md):
// every layer in typed records, in file order, with token → index maps and every
// reference the devkit resolves at load checked (plus node references of lines and
// polygons). Parsed with simdjson on-demand: real maps are up to ~100 MB.
// Whatever the devkit loads loads here too (docs/nuscenes-input.md "Map expansion v1.3"): a JSON null
// where a token is expected reads as "" (a null link then finds the record whose own token
// is null, like the devkit's lookup of None), and null tokens, "" links, lines without
// nodes, empty holes and self-intersecting rings are reported in issues(), not thrown.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "nsg/core/issues.h"
#include "nsg/geometry/arcline.h"

namespace nsg::nuscenes {

// Position of a record in its layer's file-order vector.
using MapIndex = std::uint32_t;
inline constexpr MapIndex kNoMapIndex = 0xFFFFFFFFu;

// The record layers of the file (top-level arrays), in the devkit's order.
enum class MapLayer : std::uint8_t {
  kPolygon,
  kLine,
  kNode,
  kDrivableArea,
  kRoadSegment,
  kRoadBlock,
  kLane,
  kPedCrossing,
  kWalkway,
  kStopLine,
  kCarparkArea,
  kRoadDivider,
  kLaneDivider,
  kTrafficLight,
  kLaneConnector,
};
inline constexpr size_t kMapLayerCount = 15;
// JSON key of the layer ("lane_connector", …).
std::string_view map_layer_name(MapLayer layer);

struct MapNode {
  std::string token;
  double x_m = 0.0;
  double y_m = 0.0;
};

struct MapLine {
  std::string token;
  std::vector<std::string> node_tokens;  // ordered; may be empty (a few queenstown lines)
  std::vector<MapIndex> nodes;           // resolved node_tokens
};

struct MapHole {
  std::vector<std::string> node_tokens;
  std::vector<MapIndex> nodes;
};

struct MapPolygon {
  std::string token;
  std::vector<std::string> exterior_node_tokens;  // ring, not closed
  std::vector<MapIndex> exterior_nodes;
  std::vector<MapHole> holes;
};

// {node_token, segment_type} of lane and lane_divider records.
struct LaneDividerSegment {
  std::string node_token;
  MapIndex node = kNoMapIndex;
  std::string segment_type;  // "DOUBLE_DASHED_WHITE", "NIL", …
};

// x, y, z (m) and roll/pitch/yaw-like rx, ry, rz (rad) of traffic lights.
struct MapPose6 {
  double tx = 0.0, ty = 0.0, tz = 0.0, rx = 0.0, ry = 0.0, rz = 0.0;
};

// Fields the devkit reads are required; fields only observed in real files (marked
// "optional" below) default to empty/false/0 when absent but are type-checked if present.
struct DrivableArea {
  std::string token;
  std::vector<std::string> polygon_tokens;
  std::vector<MapIndex> polygons;  // resolved polygon_tokens; a null entry that finds no
                                   // null-token polygon is left out (issue map.unresolved_null)
};

struct RoadSegment {
  std::string token;
  std::string polygon_token;
  MapIndex polygon = kNoMapIndex;
  bool is_intersection = false;     // optional
  std::string drivable_area_token;  // optional, may be ""
};

struct RoadBlock {
  std::string token;
  std::string polygon_token;
  MapIndex polygon = kNoMapIndex;
  std::string from_edge_line_token;  // optional
  std::string to_edge_line_token;    // optional
  std::string road_segment_token;    // optional
};

struct Lane {
  std::string token;
  std::string polygon_token;
  MapIndex polygon = kNoMapIndex;
  std::string lane_type;             // optional ("CAR")
  std::string from_edge_line_token;  // optional
  std::string to_edge_line_token;    // optional
  std::vector<LaneDividerSegment> left_lane_divider_segments;
  std::vector<LaneDividerSegment> right_lane_divider_segments;
};

struct LaneConnector {
  std::string token;
  std::string polygon_token;       // optional; a rough placeholder in real maps
  MapIndex polygon = kNoMapIndex;  // kNoMapIndex if absent or not a polygon (devkit ignores it)
};

struct PedCrossing {
  std::string token;
  std::string polygon_token;
  MapIndex polygon = kNoMapIndex;
  std::string road_segment_token;  // optional
};

struct Walkway {
  std::string token;
  std::string polygon_token;
  MapIndex polygon = kNoMapIndex;
};

struct StopLine {
  std::string token;
  std::string polygon_token;
  MapIndex polygon = kNoMapIndex;
  std::string stop_line_type;  // PED_CROSSING, TURN_STOP, TRAFFIC_LIGHT, STOP_SIGN, YIELD
  std::vector<std::string> ped_crossing_tokens;
  std::vector<std::string> traffic_light_tokens;
  std::string road_block_token;  // optional, may be ""
};

struct CarparkArea {
  std::string token;
  std::string polygon_token;
  MapIndex polygon = kNoMapIndex;
  double orientation_rad = 0.0;  // optional
  std::string road_block_token;  // optional
};

struct RoadDivider {
  std::string token;
  std::string line_token;
  MapIndex line = kNoMapIndex;
  std::string road_segment_token;  // optional
};

struct LaneDivider {
  std::string token;
  std::string line_token;
  MapIndex line = kNoMapIndex;
  std::vector<LaneDividerSegment> lane_divider_segments;  // optional
};

struct TrafficLightItem {
  std::string color;  // RED / YELLOW / GREEN
  std::string shape;  // CIRCLE / LEFT / RIGHT / UP
  MapPose6 rel_pos;
  std::vector<std::string> to_road_block_tokens;
};

struct TrafficLight {
  std::string token;
  std::string line_token;
  MapIndex line = kNoMapIndex;
  std::string traffic_light_type;       // optional: VERTICAL / HORIZONTAL
  std::string from_road_block_token;    // optional
  std::vector<TrafficLightItem> items;  // optional
  MapPose6 pose;                        // optional
};

struct LaneConnectivity {
  std::vector<std::string> incoming;
  std::vector<std::string> outgoing;
};

namespace detail {
// Lets the token maps be searched with a string_view (no temporary std::string). Not
// noexcept on purpose: libstdc++ then caches each key's hash in its node, so bucket walks
// compare hashes instead of 36-byte strings (100 MB map, 600k nodes: 1.2 s instead of 2.0 s).
struct MapTokenHash {
  using is_transparent = void;
  size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
};
}  // namespace detail

// One discretized centerline (a lane or lane connector).
struct Centerline {
  std::string token;
  MapLayer layer = MapLayer::kLane;  // kLane or kLaneConnector
  std::vector<geometry::Pose2> poses;
};

class MapExpansion {
 public:
  const std::filesystem::path& file() const { return file_; }
  // The file stem ("boston-seaport"), like the devkit's map_name.
  const std::string& location() const { return location_; }
  const std::string& version() const { return version_; }
  // Defects found at load that the devkit tolerates (checks "map.*", subject naming the
  // file, layer and record); one issue per kind of defect and key, with its count.
  const Issues& issues() const { return issues_; }
  // canvas_edge: [width, height] m.
  const std::array<double, 2>& canvas_edge_m() const { return canvas_edge_m_; }

  const std::vector<MapPolygon>& polygons() const { return polygon_; }
  const std::vector<MapLine>& lines() const { return line_; }
  const std::vector<MapNode>& nodes() const { return node_; }
  const std::vector<DrivableArea>& drivable_areas() const { return drivable_area_; }
  const std::vector<RoadSegment>& road_segments() const { return road_segment_; }
  const std::vector<RoadBlock>& road_blocks() const { return road_block_; }
  const std::vector<Lane>& lanes() const { return lane_; }
  const std::vector<PedCrossing>& ped_crossings() const { return ped_crossing_; }
  const std::vector<Walkway>& walkways() const { return walkway_; }
  const std::vector<StopLine>& stop_lines() const { return stop_line_; }
  const std::vector<CarparkArea>& carpark_areas() const { return carpark_area_; }
  const std::vector<RoadDivider>& road_dividers() const { return road_divider_; }
  const std::vector<LaneDivider>& lane_dividers() const { return lane_divider_; }
  const std::vector<TrafficLight>& traffic_lights() const { return traffic_light_; }
  const std::vector<LaneConnector>& lane_connectors() const { return lane_connector_; }
  // Number of records of a layer.
  size_t size(MapLayer layer) const;

  // Index of `token` in `layer`, or nullopt.
  std::optional<MapIndex> find(MapLayer layer, std::string_view token) const;
  // Index of `token` in `layer`; DataError naming the file, layer and token if absent.
  MapIndex index_of(MapLayer layer, std::string_view token) const;
  // kLane or kLaneConnector if `token` is one of them, else nullopt.
  std::optional<MapLayer> centerline_layer(std::string_view token) const;

  // arcline_path_3: keys in file order; paths of a token (nullptr if the token has none).
  const std::vector<std::string>& arcline_path_tokens() const { return arcline_tokens_; }
  const std::vector<geometry::ArclinePath>* find_arcline_path(std::string_view token) const;
  // The devkit's get_arcline_path: DataError if the token has no (or an empty) entry.
  const std::vector<geometry::ArclinePath>& get_arcline_path(std::string_view token) const;

  // connectivity: keys in file order; the record of a token (nullptr if none).
  const std::vector<std::string>& connectivity_tokens() const { return connectivity_tokens_; }
  const LaneConnectivity* find_connectivity(std::string_view token) const;
  // The devkit's get_outgoing_lane_ids / get_incoming_lane_ids: DataError if missing.
  const std::vector<std::string>& outgoing(std::string_view token) const;
  const std::vector<std::string>& incoming(std::string_view token) const;

  // The devkit's discretize_lanes(tokens, r): one entry per distinct token, in the given
  // order; a token without arcline paths gives no poses. `layer` is kLane unless the token
  // is a lane connector.
  std::vector<Centerline> discretize_lanes(const std::vector<std::string>& tokens, double resolution_m) const;
  // The devkit's discretize_centerlines(r): all lanes then all lane connectors, file order.
  std::vector<Centerline> discretize_centerlines(double resolution_m) const;
  // One record's centerline (the poses of discretize_lanes for that token).
  std::vector<geometry::Pose2> discretize_lane(std::string_view token, double resolution_m) const;

 private:
  friend class MapExpansionBuilder;
  using TokenMap = std::unordered_map<std::string, MapIndex, detail::MapTokenHash, std::equal_to<>>;

  std::filesystem::path file_;
  std::string location_;
  std::string version_;
  std::array<double, 2> canvas_edge_m_{};
  Issues issues_;
  std::vector<MapPolygon> polygon_;
  std::vector<MapLine> line_;
  std::vector<MapNode> node_;
  std::vector<DrivableArea> drivable_area_;
  std::vector<RoadSegment> road_segment_;
  std::vector<RoadBlock> road_block_;
  std::vector<Lane> lane_;
  std::vector<PedCrossing> ped_crossing_;
  std::vector<Walkway> walkway_;
  std::vector<StopLine> stop_line_;
  std::vector<CarparkArea> carpark_area_;
  std::vector<RoadDivider> road_divider_;
  std::vector<LaneDivider> lane_divider_;
  std::vector<TrafficLight> traffic_light_;
  std::vector<LaneConnector> lane_connector_;
  std::array<TokenMap, kMapLayerCount> token_index_;
  std::vector<std::string> arcline_tokens_;
  std::vector<std::vector<geometry::ArclinePath>> arcline_paths_;  // parallel to arcline_tokens_
  TokenMap arcline_index_;
  std::vector<std::string> connectivity_tokens_;
  std::vector<LaneConnectivity> connectivity_;  // parallel to connectivity_tokens_
  TokenMap connectivity_index_;
};

// Loads <dataroot>/maps/expansion/<location>.json; `location` must be one of the four
// nuScenes locations (ConfigError otherwise).
MapExpansion load_map_expansion(const std::filesystem::path& dataroot, std::string_view location);
// Loads a map file directly; its location is the file stem. Throws IoError (missing or
// unreadable), ParseError (not JSON, wrong JSON type, non-finite number, truncated) or
// DataError (old version, dangling reference, invalid arcline path), each naming the
// file, the layer and record token, and what was expected.
MapExpansion load_map_expansion_file(const std::filesystem::path& path);

// What `nsgraph inspect centerlines` prints.
struct CenterlinesJsonOptions {
  double resolution_m = 2.0;
  // Only these lane / lane-connector tokens (empty = all); output order stays file order.
  std::vector<std::string> tokens;
  // ConfigError for a non-positive or non-finite resolution.
  void validate() const;
};

// Streams {"centerlines": [{"token", "layer", "poses": [[x, y, yaw], ...]}, ...],
// "edges": [[from, to], ...]}: lanes then connectors in file order, poses exactly as
// discretize_lanes at the resolution, doubles in shortest round-trip form; edges from
// every connectivity `outgoing` list in file order (only from the selected tokens when
// `tokens` is given). An outgoing token that is no lane, lane connector or arcline_path_3
// key (dangling, devkit #415/#885) gives no edge and an issue "map.dangling_connectivity"
// in `issues` (if given). One centerline is discretized at a time (no document in memory).
// ConfigError naming any token that is neither a lane nor a lane connector.
void write_centerlines_json(const MapExpansion& map, const CenterlinesJsonOptions& options, std::ostream& out,
                            Issues* issues = nullptr);

}  // namespace nsg::nuscenes
