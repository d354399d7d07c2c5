// `nsgraph inspect graph`: the lane graph of a location — counts, longest edge, map
// defects — and optionally its GeoJSON for QGIS.
#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <map>

#include "bbox_arg.h"
#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/graph/clip.h"
#include "nsg/graph/from_map.h"
#include "nsg/graph/geojson.h"
#include "nsg/graph/lane_attributes.h"

namespace nsg::cli {
namespace {

struct InspectGraphOptions {
  std::string dataroot;
  std::string location;
  std::string bbox_text;  // "xmin,ymin,xmax,ymax" in map metres, optional
  std::string geojson_path;
  graph::LaneGraphOptions graph;

  graph::TileBounds bbox() const { return parse_bbox(bbox_text); }
  void validate() const {
    graph.validate();
    if (!bbox_text.empty()) bbox();
  }
};

// The clipped part of the graph as a LaneGraph (for counts and GeoJSON of a bbox).
graph::LaneGraph subgraph(const graph::LaneGraph& whole, const graph::TileGraph& tile) {
  graph::LaneGraph g;
  for (const graph::TileNode& n : tile.nodes) g.nodes.push_back({n.x_m, n.y_m, n.junction});
  std::map<std::string, int32_t> lane_of;
  // The lane of a token in `g`, added with the whole graph's attributes on first use.
  const auto lane_index = [&](const std::string& token) {
    auto [it, fresh] = lane_of.emplace(token, static_cast<int32_t>(g.lanes.size()));
    if (fresh) {
      const graph::Lane& from = whole.lanes[whole.find_lane(token)];
      graph::Lane lane;
      lane.token = token;
      lane.is_connector = from.is_connector;
      lane.turn = from.turn;
      lane.in_intersection = from.in_intersection;
      g.lanes.push_back(lane);
    }
    return it->second;
  };
  for (const graph::TileEdge& e : tile.edges) g.edges.push_back({e.source, e.target, lane_index(e.lane_token)});
  for (const graph::TileLaneChange& c : tile.lane_changes)
    g.lane_changes.push_back({c.source, c.target, lane_index(c.from_lane_token), lane_index(c.to_lane_token)});
  return g;
}

int run(const InspectGraphOptions& o) {
  o.validate();
  const nuscenes::MapExpansion map = nuscenes::load_map_expansion(o.dataroot, o.location);
  Issues defects;
  graph::LaneGraph g = graph::build_lane_graph(map, o.graph, &defects);
  nlohmann::ordered_json out;
  out["location"] = map.location();
  out["lanes"] = map.lanes().size();
  out["lane_connectors"] = map.lane_connectors().size();
  if (!o.bbox_text.empty()) {
    const graph::TileBounds b = o.bbox();
    g = subgraph(g, graph::clip_to_tile(g, graph::SegmentIndex(g), b));
    out["bbox_m"] = {b.x_west_m, b.y_south_m, b.x_east_m, b.y_north_m};
  }
  out["nodes"] = g.nodes.size();
  out["edges"] = g.edges.size();
  out["max_edge_length_m"] = g.max_edge_length_m();
  out["max_spacing_m"] = o.graph.max_spacing_m;
  out["lane_changes"] = g.lane_changes.size();
  nlohmann::ordered_json junctions = {{"split", 0}, {"merge", 0}, {"both", 0}};
  for (const graph::Node& n : g.nodes)
    if (n.junction != graph::Junction::kNone)
      junctions[graph::junction_name(n.junction)] = junctions[graph::junction_name(n.junction)].get<int>() + 1;
  out["junctions"] = junctions;
  nlohmann::ordered_json counts = nlohmann::ordered_json::object();
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const Issue& issue : defects.items()) {
    counts[issue.check] = counts.value(issue.check, 0) + 1;
    list.push_back({{"check", issue.check}, {"token", issue.subject}, {"message", issue.message}});
  }
  out["defect_counts"] = counts;
  out["defects"] = list;
  if (!o.geojson_path.empty()) {
    graph::write_geojson_file(g, map.location(), o.geojson_path);
    out["geojson"] = o.geojson_path;
  }
  std::cout << out.dump(2) << "\n";
  return kExitOk;
}

}  // namespace

void add_inspect_graph(CLI::App& inspect, Context& ctx) {
  auto o = std::make_shared<InspectGraphOptions>();
  CLI::App* cmd = inspect.add_subcommand("graph", "Build a location's lane graph; print counts and map defects (JSON)");
  cmd->add_option("--dataroot", o->dataroot, "nuScenes root (holds maps/expansion/)")->required();
  cmd->add_option("--location", o->location, "boston-seaport, singapore-onenorth, ...")->required();
  cmd->add_option("--bbox", o->bbox_text, "Only the part inside xmin,ymin,xmax,ymax (map metres)");
  cmd->add_option("--geojson", o->geojson_path, "Also write the graph as GeoJSON (lon/lat) to this file");
  cmd->add_option("--max-spacing", o->graph.max_spacing_m, "Largest distance between nodes, metres")
      ->capture_default_str();
  cmd->add_option("--join-tolerance", o->graph.join_tolerance_m, "Lane ends closer than this are joined, metres")
      ->capture_default_str();
  cmd->add_flag("--strict", o->graph.strict, "Map defects are errors (exit 2)");
  cmd->callback([o, &ctx] { ctx.run = [o] { return run(*o); }; });
}

}  // namespace nsg::cli
