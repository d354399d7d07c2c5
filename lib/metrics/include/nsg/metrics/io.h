#pragma once
// Reading and writing graph sets: the submission format (schemas/v1/submission.schema.json) and a
// dataset's tiles of one split as its manifest lists them (tar shards or tile folders).
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"
#include "nsg/graph/clip.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/graph.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {

// Parses an already validated submission document. Throws DataError naming `file`, the
// tile key and the JSON path when the structure is still wrong.
GraphSet graphs_from_submission(const nlohmann::json& doc, const std::string& file);
// Reads JSON text; throws IoError (unreadable) or ParseError (not JSON) naming the file.
nlohmann::json read_json_file(const std::filesystem::path& path);
// Reads a file in the submission format within `limits` (validate::read_submission: the
// file size, then the value count and nesting depth, are checked before any DOM is
// built). Returns nullopt with the problem in `issues` when the limits refuse it or the
// text is not JSON (e.g. truncated); throws IoError (unreadable) naming the file.
std::optional<nlohmann::json> read_submission_file(const std::filesystem::path& path,
                                                   const validate::SubmissionLimits& limits, Issues& issues);
// Writes a submission document (schemas/v1/submission.schema.json), node and edge scores
// included; coordinates exact (a written perfect copy scores 1), scores rounded to 1/1000;
// written to a temp name and renamed.
void write_submission(const GraphSet& graphs, const std::filesystem::path& path);

// A dataset tile's lane graph as the metrics take it: pixel (u, v) nodes, edges by node
// index, the edge attributes and change labels as EdgeFlag bits. tile_graph reads the tile's
// graph.json through its one reader (io::DatasetTile::graph(): ParseError / DataError naming
// "<key>.graph.json" and the path), with a map-update tile's prior graph as Graph::prior.
Graph graph_of_tile(const graph::TileGraph& tile);
Graph tile_graph(const io::DatasetTile& tile);

// A dataset folder's tiles of `split`, exactly those its manifest.json lists
// (io::Dataset::verify_split first: the split is listed, its shards present with their
// sizes — and sha256 when `verify` — and no unlisted shard beside them). Throws IoError /
// DataError naming the manifest, the shard or the file.
GraphSet load_dataset_split(const std::filesystem::path& dataset, const std::string& split, bool verify = true);

// Ground truth: a dataset directory (its `split`) or a submission-format file, read within
// `limits` like a submission; a file the limits refuse throws DataError naming the limit.
// `sha256` (optional) receives the digest that identifies it: of the dataset's
// manifest.json (which pins every shard's sha256), or of the file's bytes.
GraphSet load_ground_truth(const std::filesystem::path& path, const std::string& split,
                           const validate::SubmissionLimits& limits = {}, bool verify = true,
                           std::string* sha256 = nullptr);

}  // namespace nsg::metrics
