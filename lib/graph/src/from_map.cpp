#include "nsg/graph/from_map.h"

#include "nsg/graph/lane_attributes.h"

namespace nsg::graph {
namespace {

LaneSource source_of(const nuscenes::MapExpansion& map, const std::string& token, bool connector) {
  LaneSource s;
  s.token = token;
  s.is_connector = connector;
  if (const auto* paths = map.find_arcline_path(token)) s.paths = *paths;
  if (const auto* c = map.find_connectivity(token)) {
    s.outgoing = c->outgoing;
    s.incoming = c->incoming;
  } else {
    s.has_connectivity = false;
  }
  return s;
}

}  // namespace

std::vector<LaneSource> lane_sources(const nuscenes::MapExpansion& map) {
  std::vector<LaneSource> out;
  out.reserve(map.lanes().size() + map.lane_connectors().size());
  for (const auto& lane : map.lanes()) out.push_back(source_of(map, lane.token, false));
  for (const auto& c : map.lane_connectors()) out.push_back(source_of(map, c.token, true));
  return out;
}

LaneGraph build_lane_graph(const nuscenes::MapExpansion& map, const LaneGraphOptions& options, Issues* issues) {
  // The map's load defects (null tokens, "" links, degenerate geometry) come first: every
  // caller that reports graph defects (inspect graph, generate) then reports them too, and
  // --strict treats them like the graph's own.
  if (options.strict) throw_if_defects(map.issues().items(), map.file().string());
  if (issues) issues->append(map.issues());
  LaneGraph graph = build_lane_graph(lane_sources(map), options, issues, map.file().string());
  add_lane_attributes(graph);
  mark_intersections(graph, map);
  return graph;
}

}  // namespace nsg::graph
