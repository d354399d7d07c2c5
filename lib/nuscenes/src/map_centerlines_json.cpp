// The JSON view of `nsgraph inspect centerlines`, streamed record by record.
#include <cmath>
#include <ostream>
#include <unordered_set>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::nuscenes {
namespace {

void write_json_string(std::ostream& out, std::string_view s) {
  out << '"';
  for (const char ch : s) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out << '\\' << ch;
    } else if (u < 0x20) {
      out << strprintf("\\u%04x", u);
    } else {
      out << ch;
    }
  }
  out << '"';
}

void write_number(std::ostream& out, double v, const MapExpansion& map, std::string_view token) {
  if (!std::isfinite(v)) {
    throw DataError(map.file().string(), "arcline_path_3 '" + std::string(token) + "'",
                    "expected finite discretized poses (the path overflows)");
  }
  out << format_double(v);
}

// An edge target the devkit could discretize: a lane, a lane connector or any arcline key.
bool has_centerline(const MapExpansion& map, std::string_view token) {
  return map.centerline_layer(token).has_value() || map.find_arcline_path(token) != nullptr;
}

void report_dangling(const MapExpansion& map, const std::string& from, const std::string& to, Issues& issues) {
  issues.warning("map.dangling_connectivity", map.file().string() + ": connectivity '" + from + "'",
                 "key \"outgoing\" names '" + to +
                     "', which is no lane, lane connector or arcline_path_3 key; that edge is left out");
}

}  // namespace

void CenterlinesJsonOptions::validate() const {
  NSG_CHECK(std::isfinite(resolution_m) && resolution_m > 0.0, ConfigError, "", "--resolution",
            "expected a finite resolution > 0 m");
}

void write_centerlines_json(const MapExpansion& map, const CenterlinesJsonOptions& options, std::ostream& out,
                            Issues* issues) {
  options.validate();
  std::unordered_set<std::string_view> selected;
  for (const std::string& token : options.tokens) {
    if (!map.centerline_layer(token)) {
      throw ConfigError(map.file().string(), "token '" + token + "'",
                        "expected a lane or lane_connector token of this map (not found)");
    }
    selected.insert(token);
  }
  const auto wanted = [&](std::string_view token) { return selected.empty() || selected.count(token) > 0; };

  out << "{\"centerlines\": [";
  bool first = true;
  const auto write_centerline = [&](const std::string& token, MapLayer layer) {
    if (!wanted(token)) return;
    out << (first ? "\n" : ",\n") << "{\"token\": ";
    first = false;
    write_json_string(out, token);
    out << ", \"layer\": \"" << map_layer_name(layer) << "\", \"poses\": [";
    const std::vector<geometry::Pose2> poses = map.discretize_lane(token, options.resolution_m);
    for (size_t i = 0; i < poses.size(); ++i) {
      out << (i == 0 ? "[" : ", [");
      write_number(out, poses[i].x, map, token);
      out << ", ";
      write_number(out, poses[i].y, map, token);
      out << ", ";
      write_number(out, poses[i].yaw, map, token);
      out << ']';
    }
    out << "]}";
  };
  for (const Lane& lane : map.lanes()) write_centerline(lane.token, MapLayer::kLane);
  for (const LaneConnector& c : map.lane_connectors()) write_centerline(c.token, MapLayer::kLaneConnector);

  out << "\n], \"edges\": [";
  first = true;
  for (const std::string& from : map.connectivity_tokens()) {
    if (!wanted(from)) continue;
    for (const std::string& to : map.find_connectivity(from)->outgoing) {
      if (!has_centerline(map, to)) {
        if (issues) report_dangling(map, from, to, *issues);
        continue;
      }
      out << (first ? "\n[" : ",\n[");
      first = false;
      write_json_string(out, from);
      out << ", ";
      write_json_string(out, to);
      out << ']';
    }
  }
  out << "\n]}\n";
}

}  // namespace nsg::nuscenes
