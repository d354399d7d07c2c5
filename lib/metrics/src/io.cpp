#include "nsg/metrics/io.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/strings.h"
#include "nsg/io/dataset.h"
#include "nsg/io/tile_graph.h"
#include "nsg/validate/submission.h"

namespace fs = std::filesystem;

namespace nsg::metrics {
namespace {

double finite_number(const nlohmann::json& j, const std::string& file, const std::string& path) {
  NSG_CHECK(j.is_number(), DataError, file, path, "a number");
  const double x = j.get<double>();
  NSG_CHECK(std::isfinite(x), DataError, file, path, "a finite number");
  return x;
}

std::vector<double> scores(const nlohmann::json& tile, const char* name, size_t expected_size, const std::string& file,
                           const std::string& path) {
  std::vector<double> out;
  if (!tile.contains(name)) return out;
  const nlohmann::json& a = tile.at(name);
  NSG_CHECK(a.is_array() && a.size() == expected_size, DataError, file, path + "/" + name,
            "an array of " + std::to_string(expected_size) + " numbers");
  for (size_t k = 0; k < a.size(); ++k)
    out.push_back(finite_number(a[k], file, path + "/" + name + "/" + std::to_string(k)));
  return out;
}

Graph graph_from_submission_tile(const nlohmann::json& tile, const std::string& file, const std::string& path) {
  NSG_CHECK(tile.is_object(), DataError, file, path, "an object {nodes, edges}");
  NSG_CHECK(tile.contains("nodes") && tile.at("nodes").is_array(), DataError, file, path + "/nodes",
            "an array of [u, v]");
  NSG_CHECK(tile.contains("edges") && tile.at("edges").is_array(), DataError, file, path + "/edges",
            "an array of [i, j]");
  Graph g;
  const nlohmann::json& nodes = tile.at("nodes");
  g.nodes.reserve(nodes.size());
  for (size_t k = 0; k < nodes.size(); ++k) {
    const std::string p = path + "/nodes/" + std::to_string(k);
    NSG_CHECK(nodes[k].is_array() && nodes[k].size() == 2, DataError, file, p, "[u, v]");
    g.nodes.push_back({finite_number(nodes[k][0], file, p + "/0"), finite_number(nodes[k][1], file, p + "/1")});
  }
  const nlohmann::json& edges = tile.at("edges");
  const auto n = static_cast<int64_t>(g.nodes.size());
  g.edges.reserve(edges.size());
  for (size_t k = 0; k < edges.size(); ++k) {
    const std::string p = path + "/edges/" + std::to_string(k);
    NSG_CHECK(edges[k].is_array() && edges[k].size() == 2, DataError, file, p, "[i, j]");
    std::array<int64_t, 2> e{};
    for (int s = 0; s < 2; ++s) {
      const nlohmann::json& x = edges[k][s];
      NSG_CHECK(x.is_number_integer(), DataError, file, p + "/" + std::to_string(s), "an integer node index");
      e[s] = x.get<int64_t>();
      NSG_CHECK(e[s] >= 0 && e[s] < n, DataError, file, p + "/" + std::to_string(s),
                "a node index in [0, " + std::to_string(n) + ")");
    }
    g.edges.push_back(e);
  }
  g.node_scores = scores(tile, "node_scores", g.nodes.size(), file, path);
  g.edge_scores = scores(tile, "edge_scores", g.edges.size(), file, path);
  return g;
}

void insert_tile(GraphSet& set, const std::string& key, Graph graph, const std::string& file) {
  NSG_CHECK(set.emplace(key, std::move(graph)).second, DataError, file, key, "each tile key once");
}

}  // namespace

nlohmann::json read_json_file(const fs::path& path) { return parse_json_strict(read_file(path), path.string()); }

std::optional<nlohmann::json> read_submission_file(const fs::path& path, const validate::SubmissionLimits& limits,
                                                   Issues& issues) {
  // Not JSON at all (truncated, NaN) is a problem of the submission like any other
  // (validate --submission reports it the same way): in `issues`, exit 1.
  return validate::read_submission(path, limits, issues);
}

GraphSet graphs_from_submission(const nlohmann::json& doc, const std::string& file) {
  NSG_CHECK(doc.is_object(), DataError, file, "", "a JSON object {schema_version, tiles}");
  NSG_CHECK(doc.contains("tiles") && doc.at("tiles").is_object(), DataError, file, "/tiles",
            "an object of tile key -> graph");
  GraphSet out;
  for (const auto& [key, tile] : doc.at("tiles").items())
    out.emplace(key, graph_from_submission_tile(tile, file, "/tiles/" + validate::json_pointer_token(key)));
  return out;
}

namespace {

// graph.json's "change" as its EdgeFlag bit (none for an edge without a label).
uint8_t change_flag(graph::MapChange change) {
  switch (change) {
    case graph::MapChange::kUnchanged: return kEdgeUnchanged;
    case graph::MapChange::kAdded: return kEdgeAdded;
    case graph::MapChange::kRemoved: return kEdgeRemoved;
    case graph::MapChange::kMoved: return kEdgeMoved;
    case graph::MapChange::kRetyped: return kEdgeRetyped;
    case graph::MapChange::kNone: break;
  }
  return 0;
}

}  // namespace

Graph graph_of_tile(const graph::TileGraph& tile) {
  Graph g;
  g.nodes.reserve(tile.nodes.size());
  for (const graph::TileNode& n : tile.nodes) g.nodes.push_back({n.u_px, n.v_px});
  g.edges.reserve(tile.edges.size());
  for (const graph::TileEdge& e : tile.edges) g.edges.push_back({e.source, e.target});
  if (tile.has_edge_attributes) {
    g.edge_flags.reserve(tile.edges.size());
    for (const graph::TileEdge& e : tile.edges)
      g.edge_flags.push_back(static_cast<uint8_t>((e.is_connector ? kEdgeConnector : 0) |
                                                  (e.in_intersection ? kEdgeInIntersection : 0) |
                                                  change_flag(e.change)));
  }
  return g;
}

Graph tile_graph(const io::DatasetTile& tile) {
  // graph.json parsed once for both graphs (DatasetTile::graph() and prior_graph() would parse it twice).
  const std::string file = tile.key + ".graph.json";
  const nlohmann::json doc = tile.json("graph.json");
  Graph g = graph_of_tile(io::tile_graph_from_json(doc, file));
  if (const std::optional<graph::TileGraph> prior = io::tile_prior_graph_from_json(doc, file))
    g.prior = std::make_shared<const Graph>(graph_of_tile(*prior));
  return g;
}

GraphSet load_dataset_split(const fs::path& dataset, const std::string& split, bool verify) {
  const io::Dataset ds = io::Dataset::open(dataset);
  const io::SplitVerification checked = ds.verify_split(split, verify);
  GraphSet out;
  int64_t tiles = 0;
  for (const io::ShardEntry& shard : ds.shards(split)) {
    const std::vector<io::DatasetTile> read = ds.read_shard(shard);
    const std::string& name = shard.name;
    // A folder shard whose tile was deleted, or a tar cut at a member boundary, reads
    // cleanly: the manifest's count tells.
    NSG_CHECK(static_cast<int64_t>(read.size()) == shard.tiles, DataError, ds.manifest_file(), "shard '" + name + "'",
              strprintf("%lld tiles as listed, found %lld", static_cast<long long>(shard.tiles),
                        static_cast<long long>(read.size())));
    for (const io::DatasetTile& t : read) {
      // Named by the key and the shard: the file a host opens to see what is wrong.
      insert_tile(out, t.key, tile_graph(t), (dataset / "manifest.json").string() + ": shard '" + name + "'");
      ++tiles;
    }
  }
  NSG_CHECK(tiles == checked.tiles, DataError, (dataset / "manifest.json").string(), "split '" + split + "'",
            strprintf("%lld tiles as the shards list, found %lld", static_cast<long long>(checked.tiles),
                      static_cast<long long>(tiles)));
  return out;
}

GraphSet load_ground_truth(const fs::path& path, const std::string& split, const validate::SubmissionLimits& limits,
                           bool verify, std::string* sha256) {
  if (fs::is_directory(path)) {
    GraphSet out = load_dataset_split(path, split, verify);
    if (sha256 != nullptr) *sha256 = sha256_file(path / "manifest.json");
    return out;
  }
  NSG_CHECK(fs::exists(path), IoError, path.string(), "",
            "cannot open the ground truth: no such file or folder (--ground-truth takes a dataset folder or a "
            "ground-truth file in the submission format)");
  Issues issues;
  const std::optional<std::string> text = validate::read_submission_bytes(path, limits, issues);
  std::optional<nlohmann::json> doc;
  if (text) doc = validate::parse_submission_text(*text, path.string(), limits, issues);
  if (!doc) {
    NSG_CHECK(!issues.empty(), InternalError, path.string(), "", "a reason for refusing the file");
    throw DataError(path.string(), issues.items().front().check,
                    "a ground truth within the submission limits: " + issues.items().front().message);
  }
  if (sha256 != nullptr) *sha256 = sha256_hex(*text);
  return graphs_from_submission(*doc, path.string());
}

void write_submission(const metrics::GraphSet& graphs, const std::filesystem::path& path) {
  // Coordinates as the exact doubles (nlohmann writes the shortest text that reads back
  // to the same double): a perfect copy scores exactly 1 once written. Rounding them to
  // 1/1000 px moved junction nodes by up to 0.0005 px, which is enough for APLS's snapping
  // to put a node mid-segment on a neighbouring lane (0.9883 instead of 1). Scores are
  // not geometry: 1/1000 keeps them short.
  auto round3 = [](double x) { return std::round(x * 1000.0) / 1000.0; };
  nlohmann::json tiles = nlohmann::json::object();
  for (const auto& [key, g] : graphs) {
    nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
    for (const auto& n : g.nodes) nodes.push_back({n.u, n.v});
    for (const auto& e : g.edges) edges.push_back({e[0], e[1]});
    nlohmann::json t = {{"nodes", nodes}, {"edges", edges}};
    if (!g.node_scores.empty()) {
      t["node_scores"] = nlohmann::json::array();
      for (double s : g.node_scores) t["node_scores"].push_back(round3(s));
    }
    if (!g.edge_scores.empty()) {
      t["edge_scores"] = nlohmann::json::array();
      for (double s : g.edge_scores) t["edge_scores"].push_back(round3(s));
    }
    tiles[key] = std::move(t);
  }
  const nlohmann::json doc = {{"schema_version", "1"}, {"tiles", tiles}};
  write_file_atomic(path, doc.dump() + "\n");
}

}  // namespace nsg::metrics
