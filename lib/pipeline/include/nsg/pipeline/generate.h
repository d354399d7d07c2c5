#pragma once
// `generate` and `merge` (docs/architecture.md): a release in, NuScenesGraph shards,
// maps and a manifest out — in one process or as `count` shares of a cluster job.
//
// A run is a list of work items in a stable order: per location (in config order), its
// maps, then its shards of train, val and test. Every share plans every location (LiDAR
// accumulation, regions, crops: cheap and needed to number the shards) and does the items
// j with j % count == index (camera colouring and tile writing: the expensive part, only
// for its own tiles). Outputs go to temp names and are renamed; after each item the share's
// done-record (parts/share-<i>-of-<n>.json) is rewritten with the item's hashes, so a
// rerun skips verified items and redoes missing or corrupt ones. `merge` checks every
// share's record and file and writes manifest.json; a one-share run merges by itself.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/pipeline/config.h"

namespace nsg::pipeline {

struct ShareSpec {
  int index = 0;
  int count = 1;
  void validate() const;  // ConfigError
};

// --shard-index/--num-shards when given; else SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT;
// else JOB_COMPLETION_INDEX with an explicit --num-shards; else 0 of 1.
ShareSpec resolve_share(std::optional<int> index, std::optional<int> count);

struct StageTimes {
  double load_s = 0, graph_s = 0, lidar_s = 0, plan_s = 0, camera_s = 0, tiles_s = 0, merge_s = 0;
};

// The plan holds no tile at all and the run did not allow that (GenerateRun::allow_empty):
// exit code 1 ("problems found"), the message says which filter dropped the candidate
// crops at each location and what to change. Thrown by every share alike (each computes
// the whole plan), after the maps and before the done-record is completed.
class EmptyDatasetError : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitProblems; }
};

// The ladder's rung tiles this share wrote and what their LiDAR and camera work read.
struct LadderSummary {
  size_t tiles = 0;       // rung tiles written
  size_t scene_sets = 0;  // distinct scene lists accumulated (tiles that share one share the work)
  size_t sweeps = 0;      // LiDAR sweeps read for them (the split tiles' pass: GenerateSummary::sweeps)
  size_t images = 0;      // camera images decoded for them
};

struct GenerateSummary {
  std::vector<std::string> locations;
  std::vector<std::string> excluded_scenes;  // names left out by scenes.exclude (present in the release)
  size_t sweeps = 0;                         // LiDAR sweeps accumulated (every share reads all)
  size_t images = 0;                         // camera images decoded for this share's tiles
  size_t tiles_written = 0;                  // by this share, this run
  size_t items_done = 0;                     // work items finished by this share, this run
  size_t items_skipped = 0;                  // verified from an earlier run
  size_t tiles_planned = 0;                  // whole run
  bool manifest_written = false;
  LadderSummary ladder;  // generate --ladder
  StageTimes seconds;
};

struct GenerateRun {
  std::filesystem::path out;
  ShareSpec share;
  int threads = 0;  // 0 = all cores; results do not depend on it
  bool progress = true;
  bool allow_empty = false;  // write a dataset of 0 tiles instead of throwing EmptyDatasetError
  // Remove a dataset already in `out` first; without it a dataset of another config there
  // is refused (ConfigError), one of this config is resumed.
  bool overwrite = false;
  // Refuse to start (ConfigError naming the estimate and what would lower it) when the
  // estimated peak memory exceeds this many bytes; 0 = no limit. The estimate is logged
  // either way.
  uint64_t max_memory_bytes = 0;
  bool max_memory_from_machine = false;  // the limit is available_memory_bytes() (logged so)
  // Only check the inputs (config, tables, every file the run would open, the memory
  // estimate) and return: nothing is written, `out` is not needed.
  bool check_inputs_only = false;
};

// Splits that end with no tile while others have tiles are reported with log::warn.
// `config` as read through its declarations (or checked with GenerateConfig::validate).
GenerateSummary generate(const GenerateConfig& config, const GenerateRun& run);

// Verifies every share's done-record and output file under `out` and writes manifest.json.
// Throws DataError naming every missing share, missing item or corrupt file, and every
// leftover of an older dataset in the folder (a file under shards/, tiles/ or maps/ that no
// share recorded, a done-record of another share count, a manifest.json of another config),
// which `overwrite` removes instead.
void merge(const std::filesystem::path& out, bool overwrite = false);

}  // namespace nsg::pipeline
