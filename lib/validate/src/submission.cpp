#include "nsg/validate/submission.h"

#include <cmath>

namespace nsg::validate {
namespace {

bool finite_number(const nlohmann::json& j) {
  return j.is_number() && std::isfinite(j.get<double>());
}

void check_tile(const std::string& key, const nlohmann::json& tile, const std::string& file,
                const SubmissionLimits& limits, Issues& issues) {
  const std::string base = file + ":/tiles/" + json_pointer_token(key);
  if (!tile.is_object()) return;  // the schema reports it
  const nlohmann::json* nodes = tile.contains("nodes") && tile["nodes"].is_array() ? &tile["nodes"] : nullptr;
  const nlohmann::json* edges = tile.contains("edges") && tile["edges"].is_array() ? &tile["edges"] : nullptr;
  if (nodes != nullptr && static_cast<int64_t>(nodes->size()) > limits.max_nodes_per_tile)
    issues.error("submission.size", base + "/nodes",
                 std::to_string(nodes->size()) + " nodes; at most " + std::to_string(limits.max_nodes_per_tile));
  if (edges != nullptr && static_cast<int64_t>(edges->size()) > limits.max_edges_per_tile)
    issues.error("submission.size", base + "/edges",
                 std::to_string(edges->size()) + " edges; at most " + std::to_string(limits.max_edges_per_tile));
  if (nodes != nullptr) {
    for (size_t k = 0; k < nodes->size(); ++k) {
      const nlohmann::json& n = (*nodes)[k];
      if (!n.is_array()) continue;
      for (size_t s = 0; s < n.size(); ++s)
        if (n[s].is_number() && !finite_number(n[s]))
          issues.error("submission.finite", base + "/nodes/" + std::to_string(k) + "/" + std::to_string(s),
                       "a finite coordinate");
    }
  }
  const auto n_nodes = nodes != nullptr ? static_cast<int64_t>(nodes->size()) : 0;
  if (edges != nullptr) {
    for (size_t k = 0; k < edges->size(); ++k) {
      const nlohmann::json& e = (*edges)[k];
      if (!e.is_array()) continue;
      for (size_t s = 0; s < e.size(); ++s) {
        if (!e[s].is_number_integer()) continue;
        const int64_t idx = e[s].get<int64_t>();
        if (idx < 0 || idx >= n_nodes)
          issues.error("submission.indices", base + "/edges/" + std::to_string(k) + "/" + std::to_string(s),
                       "node index " + std::to_string(idx) + " out of range [0, " + std::to_string(n_nodes) + ")");
      }
    }
  }
  for (const char* name : {"node_scores", "edge_scores"}) {
    if (!tile.contains(name) || !tile[name].is_array()) continue;
    const nlohmann::json& scores = tile[name];
    const nlohmann::json* of = std::string(name) == "node_scores" ? nodes : edges;
    const size_t want = of != nullptr ? of->size() : 0;
    if (scores.size() != want)
      issues.error("submission.scores", base + "/" + name,
                   std::to_string(scores.size()) + " scores for " + std::to_string(want) +
                       (of == nodes ? " nodes" : " edges"));
    for (size_t k = 0; k < scores.size(); ++k)
      if (scores[k].is_number() && !finite_number(scores[k]))
        issues.error("submission.finite", base + "/" + name + "/" + std::to_string(k), "a finite score");
  }
}

}  // namespace

Issues check_submission_structure(const nlohmann::json& doc, const std::string& file_label,
                                  const SubmissionLimits& limits) {
  Issues issues;
  if (!doc.is_object() || !doc.contains("tiles") || !doc["tiles"].is_object()) return issues;
  for (const auto& [key, tile] : doc["tiles"].items()) check_tile(key, tile, file_label, limits, issues);
  return issues;
}

std::string json_pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

}  // namespace nsg::validate
