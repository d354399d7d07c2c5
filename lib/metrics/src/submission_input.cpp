#include "nsg/metrics/submission_input.h"

#include "nsg/core/sha256.h"
#include "nsg/metrics/io.h"
#include "nsg/validate/documents.h"
#include "nsg/validate/schema.h"

namespace nsg::metrics {

CheckedSubmission check_submission_document(const nlohmann::json& doc, const std::string& label,
                                            const std::filesystem::path& schemas_dir,
                                            const validate::SubmissionLimits& limits) {
  CheckedSubmission out;
  const std::filesystem::path dir = validate::find_schemas_dir(schemas_dir);
  out.issues =
      validate::validate_against_schema(validate::schema_path("submission", dir), doc, label, "submission.schema");
  out.issues.append(validate::check_submission_structure(doc, label, limits));
  if (out.issues.empty()) out.graphs = graphs_from_submission(doc, label);
  return out;
}

CheckedSubmission check_submission_text(const std::string& text, const std::string& label,
                                        const std::filesystem::path& schemas_dir,
                                        const validate::SubmissionLimits& limits) {
  CheckedSubmission out;
  const std::optional<nlohmann::json> doc = validate::parse_submission_text(text, label, limits, out.issues);
  if (doc) out = check_submission_document(*doc, label, schemas_dir, limits);
  out.sha256 = sha256_hex(text);
  out.bytes = static_cast<int64_t>(text.size());
  return out;
}

CheckedSubmission check_submission_file(const std::filesystem::path& file, const std::filesystem::path& schemas_dir,
                                        const validate::SubmissionLimits& limits) {
  // Read within the limits (file size, JSON values, nesting) before a DOM is built: a
  // huge or hostile file is refused, never parsed.
  // The bytes are read once: what is hashed for the receipt is what is parsed.
  CheckedSubmission out;
  const std::optional<std::string> text = validate::read_submission_bytes(file, limits, out.issues);
  if (!text) return out;
  return check_submission_text(*text, file.string(), schemas_dir, limits);
}

Issues check_graph(const Graph& graph, const std::string& key, const std::string& label,
                   const validate::SubmissionLimits& limits) {
  validate::TileValues tile;
  tile.nodes.reserve(graph.nodes.size());
  for (const Point& p : graph.nodes) tile.nodes.push_back({p.u, p.v});
  tile.edges = graph.edges;
  tile.node_scores = graph.node_scores;
  tile.edge_scores = graph.edge_scores;
  tile.has_node_scores = !graph.node_scores.empty();
  tile.has_edge_scores = !graph.edge_scores.empty();
  Issues issues;
  issues.limit_per_check(kMaxListedIssues);  // as a file's
  validate::check_tile_values(tile, label + ":/tiles/" + validate::json_pointer_token(key), limits, issues);
  return issues;
}

}  // namespace nsg::metrics
