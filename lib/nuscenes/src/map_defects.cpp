// Map defects the devkit tolerates: grouping them into issues, and the geometry checks.
#include "map_defects.h"

#include <algorithm>

#include "nsg/core/strings.h"

namespace nsg::nuscenes::map_detail {
namespace {

constexpr size_t kExamples = 3;  // records named per issue; the count says how many in all

using Point = std::array<double, 2>;

// Sign of the turn a → b → c: +1 left, −1 right, 0 collinear (exact in double for the
// map's metre coordinates: no tolerance, like shapely's validity test).
int orientation(const Point& a, const Point& b, const Point& c) {
  const double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  return (cross > 0.0) - (cross < 0.0);
}

bool on_segment(const Point& a, const Point& b, const Point& p) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
         p[1] <= std::max(a[1], b[1]);
}

bool segments_meet(const Point& a, const Point& b, const Point& c, const Point& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) || (o3 == 0 && on_segment(c, d, a)) ||
         (o4 == 0 && on_segment(c, d, b));
}

std::vector<Point> ring_points(const MapExpansion& map, const std::vector<MapIndex>& nodes) {
  std::vector<Point> out;
  out.reserve(nodes.size());
  for (const MapIndex n : nodes) out.push_back({map.nodes()[n].x_m, map.nodes()[n].y_m});
  return out;
}

}  // namespace

std::string record_label(std::string_view token, size_t index) {
  if (token.empty()) return strprintf("#%zu", index);
  std::string out = "'";
  out += token;
  out += '\'';
  return out;
}

void MapDefectLog::add(Severity severity, std::string_view check, std::string_view layer, std::string_view key,
                       std::string record, std::string_view what) {
  auto it = std::find_if(groups_.begin(), groups_.end(), [&](const Group& g) {
    return g.check == check && g.layer == layer && g.key == key && g.what == what;
  });
  if (it == groups_.end()) {
    groups_.push_back({severity, std::string(check), std::string(layer), std::string(key), std::string(what), {}, 0});
    it = groups_.end() - 1;
  }
  if (it->examples.size() < kExamples) it->examples.push_back(std::move(record));
  ++it->count;
}

Issues MapDefectLog::issues() const {
  Issues out;
  for (const Group& g : groups_) {
    std::string records;
    for (const std::string& r : g.examples) {
      if (!records.empty()) records += ", ";
      records += r;
    }
    if (g.count > g.examples.size()) records += strprintf(", … %zu more", g.count - g.examples.size());
    std::string message = strprintf("key \"%s\" ", g.key.c_str());
    message += g.what;
    message += strprintf(": %zu %s record(s) (", g.count, g.layer.c_str());
    message += records;
    message += ')';
    std::string subject = file_;
    subject += ": ";
    subject += g.layer;
    subject += ' ';
    subject += g.examples.front();
    out.add(g.severity, g.check, std::move(subject), std::move(message));
  }
  return out;
}

bool ring_self_intersects(const std::vector<Point>& points) {
  const size_t n = points.size();
  if (n < 4) return false;    // a triangle cannot cross itself
  std::vector<size_t> edges;  // edge i joins points[i] and points[(i + 1) % n]
  for (size_t i = 0; i < n; ++i)
    if (points[i] != points[(i + 1) % n]) edges.push_back(i);
  const auto lo = [&](size_t i) { return std::min(points[i][0], points[(i + 1) % n][0]); };
  const auto hi = [&](size_t i) { return std::max(points[i][0], points[(i + 1) % n][0]); };
  std::sort(edges.begin(), edges.end(), [&](size_t a, size_t b) { return lo(a) < lo(b); });
  std::vector<size_t> active;
  for (const size_t e : edges) {
    // Edges that end left of this one's start can meet no later edge either.
    std::erase_if(active, [&](size_t a) { return hi(a) < lo(e); });
    for (const size_t a : active) {
      const size_t gap = e > a ? e - a : a - e;
      if (gap == 1 || gap == n - 1) continue;  // neighbours share a node by construction
      if (segments_meet(points[a], points[(a + 1) % n], points[e], points[(e + 1) % n])) return true;
    }
    active.push_back(e);
  }
  return false;
}

void check_geometry(const MapExpansion& map, MapDefectLog& log) {
  const auto& lines = map.lines();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].node_tokens.empty())
      log.add(Severity::kWarning, "map.empty_line", "line", "node_tokens", record_label(lines[i].token, i),
              "is empty (a line with zero nodes); loaded as is, like the devkit");
  }
  const auto& polygons = map.polygons();
  for (size_t i = 0; i < polygons.size(); ++i) {
    const MapPolygon& p = polygons[i];
    const auto empty = [](const MapHole& h) { return h.nodes.empty(); };
    if (std::any_of(p.holes.begin(), p.holes.end(), empty))
      log.add(Severity::kWarning, "map.empty_hole", "polygon", "holes", record_label(p.token, i),
              "holds a hole with no nodes; loaded as is (it cuts nothing), like the devkit");
    if (ring_self_intersects(ring_points(map, p.exterior_nodes)))
      log.add(Severity::kWarning, "map.self_intersecting_polygon", "polygon", "exterior_node_tokens",
              record_label(p.token, i),
              "is a ring that crosses or touches itself; loaded as is, like the devkit (shapely calls it "
              "invalid)");
  }
}

}  // namespace nsg::nuscenes::map_detail
