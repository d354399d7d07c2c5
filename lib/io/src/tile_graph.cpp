#include "nsg/io/tile_graph.h"

#include <cmath>
#include <unordered_map>

#include "nsg/core/error.h"

namespace nsg::io {
namespace {

double number(const nlohmann::json& node, const char* name, const std::string& file, const std::string& path) {
  const auto it = node.find(name);
  NSG_CHECK(it != node.end() && it->is_number(), DataError, file, path + "/" + name, "a number");
  const double x = it->get<double>();
  NSG_CHECK(std::isfinite(x), DataError, file, path + "/" + name, "a finite number");
  return x;
}

}  // namespace

graph::TileGraph tile_graph_from_json(const nlohmann::json& doc, const std::string& file) {
  NSG_CHECK(doc.is_object() && doc.contains("nodes") && doc["nodes"].is_array() && doc.contains("edges") &&
                doc["edges"].is_array(),
            DataError, file, "", "a graph object with arrays nodes and edges");
  graph::TileGraph g;
  std::unordered_map<int64_t, int32_t> index_of;
  const nlohmann::json& nodes = doc["nodes"];
  g.nodes.reserve(nodes.size());
  for (size_t k = 0; k < nodes.size(); ++k) {
    const std::string p = "/nodes/" + std::to_string(k);
    const nlohmann::json& n = nodes[k];
    NSG_CHECK(n.is_object() && n.contains("id") && n["id"].is_number_integer(), DataError, file, p + "/id",
              "a node {id (integer), u, v, x, y}");
    const auto id = n["id"].get<int64_t>();
    NSG_CHECK(index_of.emplace(id, static_cast<int32_t>(k)).second, DataError, file, p + "/id", "a unique node id");
    g.nodes.push_back({static_cast<int32_t>(id), number(n, "u", file, p), number(n, "v", file, p),
                       number(n, "x", file, p), number(n, "y", file, p)});
  }
  const nlohmann::json& edges = doc["edges"];
  g.edges.reserve(edges.size());
  for (size_t k = 0; k < edges.size(); ++k) {
    const std::string p = "/edges/" + std::to_string(k);
    const nlohmann::json& e = edges[k];
    NSG_CHECK(e.is_object(), DataError, file, p, "an edge {source, target, lane_token}");
    graph::TileEdge edge;
    for (const char* end : {"source", "target"}) {
      const auto it = e.find(end);
      const auto found = it != e.end() && it->is_number_integer() ? index_of.find(it->get<int64_t>()) : index_of.end();
      NSG_CHECK(found != index_of.end(), DataError, file, p + "/" + end, "the id of a node of this graph");
      (std::string(end) == "source" ? edge.source : edge.target) = found->second;
    }
    const auto token = e.find("lane_token");
    NSG_CHECK(token != e.end() && token->is_string(), DataError, file, p + "/lane_token", "a lane token string");
    edge.lane_token = token->get<std::string>();
    g.edges.push_back(std::move(edge));
  }
  return g;
}

std::string tile_graph_text(const std::string& key, const graph::TileGraph& graph) {
  nlohmann::ordered_json nodes = nlohmann::ordered_json::array();
  for (const graph::TileNode& n : graph.nodes)
    nodes.push_back({{"id", n.id}, {"u", n.u_px}, {"v", n.v_px}, {"x", n.x_m}, {"y", n.y_m}});
  nlohmann::ordered_json edges = nlohmann::ordered_json::array();
  // TileEdge holds node indices; the file names nodes by id (clip_to_tile's ids are the
  // indices, a graph read back keeps the file's ids).
  const auto id_of = [&](int32_t index) { return graph.nodes.at(static_cast<size_t>(index)).id; };
  for (const graph::TileEdge& e : graph.edges)
    edges.push_back({{"source", id_of(e.source)}, {"target", id_of(e.target)}, {"lane_token", e.lane_token}});
  const nlohmann::ordered_json doc = {{"schema_version", "1"}, {"key", key}, {"nodes", nodes}, {"edges", edges}};
  return doc.dump() + "\n";
}

}  // namespace nsg::io
