#pragma once
// Structural checks of a submission beyond its schema: node indices in range,
// finite coordinates, score arrays as long as what they score, size limits that protect
// the scorer. Each problem names the tile key and the JSON path.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"

namespace nsg::validate {

// Scoring costs O(nodes x edges) per tile (APLS runs shortest paths from every node), so
// the per-tile limits bound its time: docs/scoring-limits.md derives them and measures an
// adversarial tile at the limits. A real 256-px tile holds 100-1 500 nodes at 2 m spacing.
struct SubmissionLimits {
  int64_t max_nodes_per_tile = 5000;
  int64_t max_edges_per_tile = 10000;
  double max_edge_length_px_per_tile = 100000;  // sum of edge lengths; 400 tile widths
  // APLS searches shortest paths from every node over its connected piece: the sum over
  // connected pieces of nodes x (nodes + 2 x edges). 10 M = one connected lane graph of
  // ~1 800 nodes (the busiest plausible junction tile: 7.4 M); <= 2 s per tile on one core.
  int64_t max_path_work_per_tile = 10'000'000;
  // The searches of APLS (both graphs, the other one split at the snaps) and TOPO, counted
  // while a tile is scored against its ground truth (metrics::SearchWorkExceeded): what
  // bounds the time when the ground truth is connected (about 9 ns a unit: <= 2 s per
  // tile on one core). A perfect copy of the busiest plausible connected junction spends
  // 0.72 of it, of a 16-lane one 0.90 (docs/scoring-limits.md).
  int64_t max_search_work_per_tile = 160'000'000;
  // Node coordinates within ±this many px (400 tile widths of a 256-px tile): every squared
  // distance and sum a metric takes stays finite (two nodes at ±1e160 made Chamfer inf).
  double max_abs_coordinate_px = 100000;
  // Checked before parsing, so a huge or hostile file costs neither memory nor time.
  int64_t max_file_bytes = int64_t{128} << 20;
  int64_t max_json_values = 10'000'000;  // numbers, strings, arrays, … in the whole file
  int max_depth = 16;                    // the format nests 5 deep
  void validate() const;                 // throws ConfigError
};

// Check names: submission.indices, submission.finite, submission.scores, submission.size.
// A key escaped as one JSON Pointer reference token (RFC 6901: ~ → ~0, / → ~1).
std::string json_pointer_token(const std::string& key);

Issues check_submission_structure(const nlohmann::json& doc, const std::string& file_label,
                                  const SubmissionLimits& limits = {});

// One submission tile as numbers: what check_submission_structure reads of a file's tile,
// and what a graph in memory is checked as (metrics::check_graph), so both meet one check.
struct TileValues {
  std::vector<std::array<double, 2>> nodes;   // [u, v] px
  std::vector<std::array<int64_t, 2>> edges;  // node indices as given; out of range is reported
  std::vector<double> node_scores, edge_scores;
  bool has_node_scores = false, has_edge_scores = false;
  // Elements a file holds in a shape the schema refuses (it reports them): left out of
  // every check here. Empty: all read.
  std::vector<bool> node_unread, edge_unread;
};

// The checks of one tile (submission.size, .finite, .indices, .scores), subjects under
// `base` ("file:/tiles/<key>").
void check_tile_values(const TileValues& tile, const std::string& base, const SubmissionLimits& limits, Issues& issues);

// The scoring limits on one tile's graph (submission.size issues naming `subject`): the
// one check behind `score`, check_submission, score_tile and the Python score.
// `edge_length_px` is the sum of the edge lengths (edges with valid indices).
void check_tile_limits(int64_t nodes, int64_t edges, double edge_length_px, int64_t path_work,
                       const std::string& subject, const SubmissionLimits& limits, Issues& issues);
// The APLS shortest-path work of a graph (see max_path_work_per_tile); edges with an index
// outside [0, nodes) are ignored.
int64_t path_search_work(int64_t nodes, const std::vector<std::array<int64_t, 2>>& edges);

// Reads a submission within the limits: file size first, then a streaming pass counting
// values and depth, then the parse. Returns nullopt with the problem in `issues`
// (submission.size, or submission.json for invalid JSON such as NaN); throws IoError
// if the file cannot be read.
// A pipe or /dev/stdin is read up to the byte limit (it has no size to check up front).
// A key repeated within one object is a submission.json problem (JSON leaves its meaning
// open; keeping the last could swing a score).
std::optional<nlohmann::json> read_submission(const std::filesystem::path& file, const SubmissionLimits& limits,
                                              Issues& issues);
// The file's bytes within the byte limit (the first step of read_submission): nullopt with a
// submission.size issue beyond it; throws IoError if the file cannot be read.
std::optional<std::string> read_submission_bytes(const std::filesystem::path& file, const SubmissionLimits& limits,
                                                 Issues& issues);
// The same checks on submission text already in memory; `label` names it in the issues.
std::optional<nlohmann::json> parse_submission_text(const std::string& text, const std::string& label,
                                                    const SubmissionLimits& limits, Issues& issues);

// Tile keys of one split of a dataset, sorted. Taken from the manifest's shard key ranges
// when they are contiguous, else by reading the shards.
std::vector<std::string> dataset_split_keys(const std::filesystem::path& dataset, const std::string& split);

struct SubmissionValidateOptions {
  std::filesystem::path submission;
  std::filesystem::path dataset;  // "" = no key checks
  std::string split = "test";
  std::filesystem::path schemas_dir;  // "" = find_schemas_dir()
  SubmissionLimits limits;
  void validate() const;  // throws ConfigError
};

struct SubmissionReport {
  Issues issues;                          // errors make the submission invalid
  std::vector<std::string> missing_keys;  // dataset keys absent (scored as empty); also warnings
  int64_t tiles = 0;                      // tiles in the submission
  bool parsed = false;                    // false: refused before parsing (size, JSON)
};

// Check names: submission.json, submission.size, submission.schema, submission.keys
// (unknown key: error), submission.missing (warning), plus check_submission_structure's.
SubmissionReport validate_submission(const SubmissionValidateOptions& options);

}  // namespace nsg::validate
