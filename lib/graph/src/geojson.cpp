#include "nsg/graph/geojson.h"

#include <cmath>
#include <numbers>
#include <sstream>

#include "nsg/core/atomic_file.h"
#include "nsg/core/strings.h"
#include "nsg/geometry/georef.h"
#include "nsg/graph/lane_attributes.h"

namespace nsg::graph {
namespace {

// JSON string body for tokens (map tokens are plain, but be safe with quotes/backslashes).
std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      out += strprintf("\\u%04x", c);
      continue;
    }
    out += c;
  }
  return out + "\"";
}

void write_position(std::ostream& out, const geometry::LonLat& p) {
  out << '[' << format_double(p.lon_deg) << ", " << format_double(p.lat_deg) << ']';
}

void write_line(std::ostream& out, const geometry::AzimuthalProjection& projection, const Node& a, const Node& b) {
  out << "{\"type\": \"LineString\", \"coordinates\": [";
  write_position(out, projection.to_lonlat(a.x_m, a.y_m));
  out << ", ";
  write_position(out, projection.to_lonlat(b.x_m, b.y_m));
  out << "]}";
}

// After the successor edges: one LineString per lane change (kind "lane_change"), so a QGIS
// style can show or hide them by kind.
void write_lane_changes(const LaneGraph& graph, const geometry::AzimuthalProjection& projection, std::ostream& out) {
  for (const LaneChange& c : graph.lane_changes) {
    out << ",\n{\"type\": \"Feature\", \"properties\": {\"kind\": \"lane_change\", \"source\": " << c.source
        << ", \"target\": " << c.target << ", \"from_lane_token\": " << json_string(graph.lanes[c.source_lane].token)
        << ", \"to_lane_token\": " << json_string(graph.lanes[c.target_lane].token) << "}, \"geometry\": ";
    write_line(out, projection, graph.nodes[c.source], graph.nodes[c.target]);
    out << "}";
  }
}

// Then one Point per fork or join (kind "junction").
void write_junctions(const LaneGraph& graph, const geometry::AzimuthalProjection& projection, std::ostream& out) {
  for (size_t k = 0; k < graph.nodes.size(); ++k) {
    const Node& n = graph.nodes[k];
    if (n.junction == Junction::kNone) continue;
    out << ",\n{\"type\": \"Feature\", \"properties\": {\"kind\": \"junction\", \"node\": " << k << ", \"junction\": \""
        << junction_name(n.junction) << "\"}, \"geometry\": {\"type\": \"Point\", \"coordinates\": ";
    write_position(out, projection.to_lonlat(n.x_m, n.y_m));
    out << "}}";
  }
}

}  // namespace

void write_geojson(const LaneGraph& graph, std::string_view location, std::ostream& out) {
  const geometry::AzimuthalProjection projection(location);
  out << "{\"type\": \"FeatureCollection\",\n\"name\": " << json_string(std::string(location) + " lane graph")
      << ",\n\"features\": [";
  for (size_t e = 0; e < graph.edges.size(); ++e) {
    const Edge& edge = graph.edges[e];
    const Node& a = graph.nodes[edge.source];
    const Node& b = graph.nodes[edge.target];
    const Lane& lane = graph.lanes[edge.lane];
    // Bearing clockwise from map north, the way a map reader states a direction.
    // In [0, 360) after rounding to 0.01°: 359.996 is 0, not 360; +0.0 turns −0 into 0.
    double bearing = std::atan2(b.x_m - a.x_m, b.y_m - a.y_m) * 180.0 / std::numbers::pi;
    if (bearing < 0) bearing += 360.0;
    bearing = std::round(bearing * 100.0) / 100.0;
    if (bearing >= 360.0) bearing -= 360.0;
    bearing += 0.0;
    out << (e ? ",\n" : "\n") << "{\"type\": \"Feature\", \"properties\": {\"lane_token\": " << json_string(lane.token)
        << ", \"layer\": \"" << (lane.is_connector ? "lane_connector" : "lane")
        << "\", \"kind\": \"successor\", \"source\": " << edge.source << ", \"target\": " << edge.target
        << ", \"bearing_deg\": " << format_double(bearing)
        << ", \"in_intersection\": " << (lane.in_intersection ? "true" : "false") << ", \"turn\": \""
        << turn_name(lane.turn) << "\"}, \"geometry\": ";
    write_line(out, projection, a, b);
    out << "}";
  }
  write_lane_changes(graph, projection, out);
  write_junctions(graph, projection, out);
  out << "\n]}\n";
}

void write_geojson_file(const LaneGraph& graph, std::string_view location, const std::string& path) {
  std::ostringstream text;
  write_geojson(graph, location, text);
  write_file_atomic(path, text.str());
}

}  // namespace nsg::graph
