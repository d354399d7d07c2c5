#pragma once
// Structural checks of a submission beyond its schema (issue 7): node indices in range,
// finite coordinates, score arrays as long as what they score, size limits that protect
// the scorer. Each problem names the tile key and the JSON path.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"

namespace nsg::validate {

struct SubmissionLimits {
  int64_t max_nodes_per_tile = 100000;
  int64_t max_edges_per_tile = 400000;
};

// Check names: submission.indices, submission.finite, submission.scores, submission.size.
// A key escaped as one JSON Pointer reference token (RFC 6901: ~ → ~0, / → ~1).
std::string json_pointer_token(const std::string& key);

Issues check_submission_structure(const nlohmann::json& doc, const std::string& file_label,
                                  const SubmissionLimits& limits = {});

}  // namespace nsg::validate
