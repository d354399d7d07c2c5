#pragma once
// A share's done-record, parts/share-<i>-of-<n>.json: what one `generate --share i/n` has
// written and verified, rewritten after every item, and what `merge` turns into the
// manifest (docs/dataset-format.md "Sharded runs"). Its one model, one writer
// (done_record_text) and one reader (read_done_record, within the format's limits): every
// module that looks at a done-record — generate's resume, merge, --overwrite's list of our
// files — goes through them.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/io/manifest.h"
#include "nsg/pipeline/config.h"

namespace nsg::pipeline {

// A record lists a share's items and the run's plan; a full nuScenes run's is ≈ 2 MB.
inline constexpr int64_t kMaxDoneRecordBytes = int64_t{128} << 20;
inline constexpr int kMaxDoneRecordDepth = 16;  // the format nests 8 deep (plan shards)

struct DoneFile {
  std::string file;  // relative to the dataset folder (stays_inside)
  std::string sha256;
  int64_t bytes = 0;
};

// One work item a share wrote: a location's maps ("maps/<location>") or a shard
// ("shards/<name>.tar" or "tiles/<name>").
struct DoneItem {
  std::string id;
  std::string kind;  // "maps" or "shard"
  std::string location;
  std::string split;  // shard items: the split (or rung split), the shard's name, its tiles
  std::string shard;
  int64_t tiles = 0;
  std::vector<DoneFile> files;
  std::string digest;  // item_digest(files): a folder-layout shard's manifest sha256
};

struct DoneRecord {
  std::filesystem::path path;  // where it was read from ("" when built to be written)
  std::string tool_version;
  int share_index = 0;
  int share_count = 1;
  std::string config_sha256;
  // The run's config as config_to_json wrote it (merge copies it into the manifest byte for
  // byte) and as config_from_json reads it.
  nlohmann::ordered_json config_json;
  GenerateConfig config;
  bool complete = false;
  // The plan's locations (the manifest's `locations`), [] until the share completes: as
  // written (shares are compared by it) and as io::manifest_locations_from_json reads it.
  nlohmann::ordered_json plan_json = nlohmann::ordered_json::array();
  std::vector<io::ManifestLocation> plan;
  std::vector<DoneItem> items;
};

// The record's bytes (1-space indent, final newline), fields in the schema's order
// (schemas/v1/done-record.schema.json); `config` and `plan` are not read, the JSON forms are.
std::string done_record_text(const DoneRecord& record);
// An item as the record and the manifest's hashing see it.
nlohmann::ordered_json done_item_json(const DoneItem& item);

// The record at `path`: its size bounded before it is read (kMaxDoneRecordBytes), parsed
// strictly (depth, repeated keys), every field typed and checked — files inside the dataset
// folder, the config through config_from_json, the plan through the manifest's reader.
// ParseError naming the file and the JSON pointer; IoError when missing or unreadable.
DoneRecord read_done_record(const std::filesystem::path& path);
// The same for a record's text; `file` names it in errors.
DoneRecord done_record_from_text(std::string_view text, const std::filesystem::path& file);

}  // namespace nsg::pipeline
