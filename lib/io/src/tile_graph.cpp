#include "nsg/io/tile_graph.h"

#include <cmath>
#include <optional>
#include <unordered_map>

#include "nsg/core/error.h"
#include "nsg/core/issues.h"
#include "nsg/graph/lane_attributes.h"
#include "nsg/graph/map_changes.h"

namespace nsg::io {
namespace {

double number(const nlohmann::json& node, const char* name, const std::string& file, const std::string& path) {
  const auto it = node.find(name);
  NSG_CHECK(it != node.end() && it->is_number(), DataError, file, path + "/" + name, "a number");
  const double x = it->get<double>();
  NSG_CHECK(std::isfinite(x), DataError, file, path + "/" + name, "a finite number");
  return x;
}

int32_t node_index(const nlohmann::json& record, const char* end, const std::unordered_map<int64_t, int32_t>& index_of,
                   const std::string& file, const std::string& path) {
  const auto it = record.find(end);
  const auto found = it != record.end() && it->is_number_integer() ? index_of.find(it->get<int64_t>()) : index_of.end();
  NSG_CHECK(found != index_of.end(), DataError, file, path + "/" + end, "the id of a node of this graph");
  return found->second;
}

std::string text(const nlohmann::json& record, const char* name, const std::string& file, const std::string& path) {
  const auto it = record.find(name);
  NSG_CHECK(it != record.end() && it->is_string(), DataError, file, path + "/" + name, "a lane token string");
  return it->get<std::string>();
}

// The optional node attribute (a graph written before attributes has none: "none").
graph::Junction junction(const nlohmann::json& node, const std::string& file, const std::string& path) {
  graph::Junction out = graph::Junction::kNone;
  const auto it = node.find("junction");
  NSG_CHECK(it == node.end() || (it->is_string() && graph::junction_from_name(it->get<std::string>(), &out)), DataError,
            file, path + "/junction", "\"none\", \"split\", \"merge\" or \"both\"");
  return out;
}

// The optional edge attributes: kind, in_intersection, turn.
// Returns whether the edge has them (its "kind").
bool read_edge_attributes(const nlohmann::json& e, const std::string& file, const std::string& path,
                          graph::TileEdge& edge) {
  const auto kind = e.find("kind");
  if (kind != e.end()) {
    NSG_CHECK(*kind == "lane" || *kind == "connector", DataError, file, path + "/kind", "\"lane\" or \"connector\"");
    edge.is_connector = *kind == "connector";
  }
  if (const auto in = e.find("in_intersection"); in != e.end()) {
    NSG_CHECK(in->is_boolean(), DataError, file, path + "/in_intersection", "true or false");
    edge.in_intersection = in->get<bool>();
  }
  if (const auto turn = e.find("turn"); turn != e.end())
    NSG_CHECK(turn->is_string() && graph::turn_from_name(turn->get<std::string>(), &edge.turn), DataError, file,
              path + "/turn", "\"straight\", \"left\", \"right\" or \"u_turn\"");
  if (const auto change = e.find("change"); change != e.end())
    NSG_CHECK(change->is_string() && graph::map_change_from_name(change->get<std::string>(), &edge.change), DataError,
              file, path + "/change", "\"unchanged\", \"added\", \"removed\", \"moved\" or \"retyped\"");
  return kind != e.end();
}

// The graph object at `at` of the document ("" the document itself, "/prior" a map-update
// tile's prior graph): its nodes, edges and lane changes.
graph::TileGraph graph_object(const nlohmann::json& doc, const std::string& file, const std::string& at,
                              Issues* problems) {
  NSG_CHECK(doc.is_object() && doc.contains("nodes") && doc["nodes"].is_array() && doc.contains("edges") &&
                doc["edges"].is_array(),
            DataError, file, at, "a graph object with arrays nodes and edges");
  // A reference problem (a repeated id, an end that names no node) throws, or is listed
  // under its check when the caller collects them; the edge or lane change is then left out.
  const auto reference = [&](const char* check, const DataError& e) {
    if (problems == nullptr) throw e;
    problems->error(check, file + ":" + e.record(), e.expected());
  };
  graph::TileGraph g;
  std::unordered_map<int64_t, int32_t> index_of;
  const nlohmann::json& nodes = doc["nodes"];
  g.nodes.reserve(nodes.size());
  for (size_t k = 0; k < nodes.size(); ++k) {
    const std::string p = at + "/nodes/" + std::to_string(k);
    const nlohmann::json& n = nodes[k];
    NSG_CHECK(n.is_object() && n.contains("id") && n["id"].is_number_integer(), DataError, file, p + "/id",
              "a node {id (integer), u, v, x, y}");
    const auto id = n["id"].get<int64_t>();
    if (!index_of.emplace(id, static_cast<int32_t>(k)).second)
      reference("graph.indices", DataError(file, p + "/id", "a unique node id, got " + std::to_string(id) + " again"));
    g.nodes.push_back({static_cast<int32_t>(id), number(n, "u", file, p), number(n, "v", file, p),
                       number(n, "x", file, p), number(n, "y", file, p), junction(n, file, p)});
  }
  // An edge's or a lane change's two node indices; false when one names no node (listed).
  const auto ends = [&](const nlohmann::json& r, const std::string& p, const char* check, int32_t* source,
                        int32_t* target) {
    try {
      *source = node_index(r, "source", index_of, file, p);
      *target = node_index(r, "target", index_of, file, p);
      return true;
    } catch (const DataError& bad) {
      reference(check, bad);
      return false;
    }
  };
  const nlohmann::json& edges = doc["edges"];
  g.edges.reserve(edges.size());
  for (size_t k = 0; k < edges.size(); ++k) {
    const std::string p = at + "/edges/" + std::to_string(k);
    const nlohmann::json& e = edges[k];
    NSG_CHECK(e.is_object(), DataError, file, p, "an edge {source, target, lane_token}");
    graph::TileEdge edge;
    if (!ends(e, p, "graph.indices", &edge.source, &edge.target)) continue;
    edge.lane_token = text(e, "lane_token", file, p);
    if (!read_edge_attributes(e, file, p, edge)) g.has_edge_attributes = false;
    g.edges.push_back(std::move(edge));
  }
  const auto changes = doc.find("lane_changes");
  if (changes == doc.end()) return g;
  NSG_CHECK(changes->is_array(), DataError, file, at + "/lane_changes", "an array of lane changes");
  g.lane_changes.reserve(changes->size());
  for (size_t k = 0; k < changes->size(); ++k) {
    const std::string p = at + "/lane_changes/" + std::to_string(k);
    const nlohmann::json& c = (*changes)[k];
    NSG_CHECK(c.is_object(), DataError, file, p, "a lane change {source, target, from_lane_token, to_lane_token}");
    graph::TileLaneChange change;
    if (!ends(c, p, "graph.lane_changes", &change.source, &change.target)) continue;
    change.from_lane_token = text(c, "from_lane_token", file, p);
    change.to_lane_token = text(c, "to_lane_token", file, p);
    g.lane_changes.push_back(std::move(change));
  }
  return g;
}

}  // namespace

graph::TileGraph tile_graph_from_json(const nlohmann::json& doc, const std::string& file, Issues* problems) {
  return graph_object(doc, file, "", problems);
}

std::optional<graph::TileGraph> tile_prior_graph_from_json(const nlohmann::json& doc, const std::string& file,
                                                           Issues* problems) {
  if (!doc.is_object() || !doc.contains("prior")) return std::nullopt;
  return graph_object(doc["prior"], file, "/prior", problems);
}

namespace {

// {nodes, edges, lane_changes} of one graph, edges naming their nodes by TileNode::id.
nlohmann::ordered_json graph_members(const graph::TileGraph& graph) {
  nlohmann::ordered_json nodes = nlohmann::ordered_json::array();
  for (const graph::TileNode& n : graph.nodes)
    nodes.push_back({{"id", n.id},
                     {"u", n.u_px},
                     {"v", n.v_px},
                     {"x", n.x_m},
                     {"y", n.y_m},
                     {"junction", graph::junction_name(n.junction)}});
  nlohmann::ordered_json edges = nlohmann::ordered_json::array();
  // TileEdge holds node indices; the file names nodes by id (clip_to_tile's ids are the
  // indices, a graph read back keeps the file's ids).
  const auto id_of = [&](int32_t index) { return graph.nodes.at(static_cast<size_t>(index)).id; };
  for (const graph::TileEdge& e : graph.edges)
    edges.push_back({{"source", id_of(e.source)},
                     {"target", id_of(e.target)},
                     {"lane_token", e.lane_token},
                     {"kind", e.is_connector ? "connector" : "lane"},
                     {"in_intersection", e.in_intersection},
                     {"turn", graph::turn_name(e.turn)}});
  for (size_t k = 0; k < graph.edges.size(); ++k)
    if (graph.edges[k].change != graph::MapChange::kNone)
      edges[k]["change"] = graph::map_change_name(graph.edges[k].change);
  nlohmann::ordered_json lane_changes = nlohmann::ordered_json::array();
  for (const graph::TileLaneChange& c : graph.lane_changes)
    lane_changes.push_back({{"source", id_of(c.source)},
                            {"target", id_of(c.target)},
                            {"from_lane_token", c.from_lane_token},
                            {"to_lane_token", c.to_lane_token}});
  return {{"nodes", nodes}, {"edges", edges}, {"lane_changes", lane_changes}};
}

}  // namespace

std::string tile_graph_text(const std::string& key, const graph::TileGraph& graph, const graph::TileGraph* prior) {
  nlohmann::ordered_json doc = {{"schema_version", "1"}, {"key", key}};
  const nlohmann::ordered_json members = graph_members(graph);
  for (const auto& [name, value] : members.items()) doc[name] = value;
  if (prior != nullptr) doc["prior"] = graph_members(*prior);
  return doc.dump() + "\n";
}

}  // namespace nsg::io
