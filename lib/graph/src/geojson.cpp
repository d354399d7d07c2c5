#include "nsg/graph/geojson.h"

#include <cmath>
#include <numbers>
#include <sstream>

#include "nsg/core/atomic_file.h"
#include "nsg/core/strings.h"
#include "nsg/geometry/georef.h"

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
        << ", \"layer\": \"" << (lane.is_connector ? "lane_connector" : "lane") << "\", \"source\": " << edge.source
        << ", \"target\": " << edge.target << ", \"bearing_deg\": " << format_double(bearing)
        << "}, \"geometry\": {\"type\": \"LineString\", \"coordinates\": [";
    write_position(out, projection.to_lonlat(a.x_m, a.y_m));
    out << ", ";
    write_position(out, projection.to_lonlat(b.x_m, b.y_m));
    out << "]}}";
  }
  out << "\n]}\n";
}

void write_geojson_file(const LaneGraph& graph, std::string_view location, const std::string& path) {
  std::ostringstream text;
  write_geojson(graph, location, text);
  write_file_atomic(path, text.str());
}

}  // namespace nsg::graph
