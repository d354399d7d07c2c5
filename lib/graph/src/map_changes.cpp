#include "nsg/graph/map_changes.h"

#include <algorithm>
#include <cmath>

namespace nsg::graph {

namespace {

constexpr double kYawToleranceRad = 1e-4;

bool same_paths(const std::vector<geometry::ArclinePath>& a, const std::vector<geometry::ArclinePath>& b) {
  if (a.size() != b.size()) return false;
  const auto near = [](double x, double y, double tol) { return std::fabs(x - y) <= tol; };
  for (size_t i = 0; i < a.size(); ++i) {
    const geometry::ArclinePath& p = a[i];
    const geometry::ArclinePath& q = b[i];
    if (p.shape != q.shape || !near(p.start_pose.x, q.start_pose.x, kMovedToleranceM) ||
        !near(p.start_pose.y, q.start_pose.y, kMovedToleranceM) ||
        !near(std::remainder(p.start_pose.yaw - q.start_pose.yaw, 2.0 * 3.141592653589793), 0.0, kYawToleranceRad) ||
        !near(p.radius_m, q.radius_m, kMovedToleranceM))
      return false;
    for (size_t k = 0; k < 3; ++k)
      if (!near(p.segment_length_m[k], q.segment_length_m[k], kMovedToleranceM)) return false;
  }
  return true;
}

// Each lane's divider segment types, both sides in order, by token (connectors have none).
std::map<std::string, std::string> divider_types(const nuscenes::MapExpansion& map) {
  std::map<std::string, std::string> out;
  for (const nuscenes::Lane& lane : map.lanes()) {
    std::string& types = out[lane.token];
    for (const auto* side : {&lane.left_lane_divider_segments, &lane.right_lane_divider_segments}) {
      for (const nuscenes::LaneDividerSegment& s : *side) types += s.segment_type + ",";
      types += "|";
    }
  }
  return out;
}

}  // namespace

std::map<std::string, MapChange> lane_changes_between(const nuscenes::MapExpansion& prior,
                                                      const nuscenes::MapExpansion& current) {
  std::map<std::string, MapChange> out;
  const std::map<std::string, std::string> types_before = divider_types(prior), types_now = divider_types(current);
  const auto types = [](const std::map<std::string, std::string>& m, const std::string& t) {
    const auto it = m.find(t);
    return it == m.end() ? std::string() : it->second;
  };
  // The lanes and connectors of a map are its arcline paths' tokens (the lane graph's too).
  for (const std::string& t : current.arcline_path_tokens()) {
    const auto* before = prior.find_arcline_path(t);
    if (before == nullptr) {
      out[t] = MapChange::kAdded;
    } else if (!same_paths(*before, current.get_arcline_path(t))) {
      out[t] = MapChange::kMoved;
    } else {
      out[t] = types(types_before, t) == types(types_now, t) ? MapChange::kUnchanged : MapChange::kRetyped;
    }
  }
  for (const std::string& t : prior.arcline_path_tokens())
    if (current.find_arcline_path(t) == nullptr) out[t] = MapChange::kRemoved;
  return out;
}

void label_map_changes(TileGraph& graph, const std::map<std::string, MapChange>& labels) {
  for (TileEdge& e : graph.edges) {
    const auto it = labels.find(e.lane_token);
    e.change = it == labels.end() ? MapChange::kNone : it->second;
  }
}

const char* map_change_name(MapChange change) {
  switch (change) {
    case MapChange::kNone: return "";
    case MapChange::kUnchanged: return "unchanged";
    case MapChange::kAdded: return "added";
    case MapChange::kRemoved: return "removed";
    case MapChange::kMoved: return "moved";
    case MapChange::kRetyped: return "retyped";
  }
  return "";
}

bool map_change_from_name(const std::string& name, MapChange* change) {
  for (const MapChange c :
       {MapChange::kUnchanged, MapChange::kAdded, MapChange::kRemoved, MapChange::kMoved, MapChange::kRetyped})
    if (name == map_change_name(c)) {
      *change = c;
      return true;
    }
  return false;
}

}  // namespace nsg::graph
