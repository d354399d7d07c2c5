#pragma once
// What `nsgraph score` does with a submission before scoring, shared with the Python
// binding so both refuse and accept the same documents: read within the size limits,
// check against schemas/v1/submission.schema.json and the structural rules, convert.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"
#include "nsg/metrics/graph.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {

struct CheckedSubmission {
  Issues issues;       // problems of the submission; non-empty = not scored (exit 1)
  GraphSet graphs;     // the tiles, when there is no problem
  std::string sha256;  // of the bytes read ("" for a document given as JSON or refused unread)
  int64_t bytes = 0;
};

// Throws IoError if the file cannot be read and when the schemas are not found
// (schemas_dir "" = validate::find_schemas_dir()).
CheckedSubmission check_submission_file(const std::filesystem::path& file,
                                        const std::filesystem::path& schemas_dir = {},
                                        const validate::SubmissionLimits& limits = {});
// The same checks on submission text in memory (not JSON, NaN, a repeated key: issues,
// never exceptions); `label` names it in the issues.
CheckedSubmission check_submission_text(const std::string& text, const std::string& label,
                                        const std::filesystem::path& schemas_dir = {},
                                        const validate::SubmissionLimits& limits = {});
// The same checks on a document already in memory; `label` names it in the issues.
CheckedSubmission check_submission_document(const nlohmann::json& doc, const std::string& label,
                                            const std::filesystem::path& schemas_dir = {},
                                            const validate::SubmissionLimits& limits = {});

// The checks a file's tile gets (validate::check_submission_structure: finite coordinates
// and scores, node indices in range, the per-tile limits) on one graph in memory, the tile
// named `key` in a document labelled `label`: what score_tile and measure() run, so a graph
// reaches the metrics only as a file's would.
Issues check_graph(const Graph& graph, const std::string& key, const std::string& label,
                   const validate::SubmissionLimits& limits = {});

}  // namespace nsg::metrics
