#pragma once
// `nsgraph validate DATASET`: the published schemas plus named structural checks
// of a generated dataset (docs/dataset-format.md). Each problem is an Issue whose check is a dotted
// name (see dataset_checks()) and whose subject names the shard, tile key and field.
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/core/issues.h"

namespace nsg::validate {

struct CheckInfo {
  std::string name;         // e.g. "graph.edge_length"
  std::string description;  // one line for --list-checks
};

// Every dataset check, in the order they run.
const std::vector<CheckInfo>& dataset_checks();

// `patterns` is a comma-separated list of wildcards ("graph.*,shard.sha256"); "" or "*" = all.
bool check_selected(const std::string& patterns, const std::string& check);

struct DatasetValidateOptions {
  std::filesystem::path root;         // dataset folder holding manifest.json
  std::filesystem::path schemas_dir;  // "" = find_schemas_dir()
  std::string checks = "*";           // see check_selected
  double length_tolerance_m = 1e-6;   // slack on graph.edge_length and position checks
  bool progress = false;              // a progress line per shard on stderr (the CLI's)
  // Throws ConfigError for an empty root or a pattern that selects no check.
  void validate() const;
};

// Runs the selected checks. Throws IoError/ParseError (exit 2) only when the manifest
// cannot be read or is not JSON; everything else is reported as issues.
Issues validate_dataset(const DatasetValidateOptions& options);

}  // namespace nsg::validate
