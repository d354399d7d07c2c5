#pragma once
// A dataset's manifest.json (docs/dataset-format.md "manifest.json",
// schemas/v1/manifest.schema.json) as types, with its one reader and its one writer. The
// reader checks every field it models and applies the format's limits in one place (file
// size, nesting, counts, value ranges, shard paths inside the dataset): io::Dataset holds
// its result, so stats, validate, score, preview, the report, the model, frames and Python
// read a manifest only through it. merge writes through manifest_to_json.
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::io {

// ---- the format's limits (the reader's, and nowhere else) ---------------------------------

// A manifest is read whole: a real nuScenes dataset's is a few MB; 128 MiB bounds the
// memory a hostile one can take before a single field is read.
inline constexpr int64_t kMaxManifestBytes = int64_t{128} << 20;
// The manifest nests 8 deep (config.splits.regions.<location>[i].bounds_m[k]).
inline constexpr int kMaxManifestDepth = 16;
// Entries of one list (shards, ladder shards, a location's shards, regions, maps, tables):
// far above any dataset, and what keeps a list read in memory bounded.
inline constexpr int64_t kMaxManifestEntries = 200000;
// A tile count (a shard's, a split's, the total): far above nuScenes' ~100 000 tiles, and
// small enough that sums over a manifest's shards cannot overflow.
inline constexpr int64_t kMaxManifestTiles = int64_t{1} << 31;
// A byte count (a shard's, a file's): 1 PiB.
inline constexpr int64_t kMaxManifestFileBytes = int64_t{1} << 50;
// A ladder rung (scenes a rung tile may use): the tile meta's bound too.
inline constexpr int kMaxRung = 100000;
// "all" in ladder.rungs: the split's own tiles (the largest rung; pipeline::kRungAll).
inline constexpr int kRungAll = std::numeric_limits<int>::max();

// ---- the model ----------------------------------------------------------------------------

// The shape of every tile: tile_format.
struct TileFormat {
  double resolution_m = 0.2;       // > 0
  int size_px = 256;               // 1 … kMaxTileSizePx (io/tile_meta.h)
  std::string key_pattern;         // "<location>-<split>-<NNNNNN>"
  std::vector<std::string> files;  // member suffixes, in the order the writer emits them
};

// A file the manifest records with its digest: a table or map of the release
// (inputs.tables, inputs.map_expansion, inputs.detections) or a dataset file (maps).
struct FileRecord {
  std::string file;    // relative to its root (the release's dataroot, or the dataset)
  std::string sha256;  // 64 lowercase hex digits
  int64_t bytes = 0;
};

// inputs.map_expansion.<location>.
struct MapExpansionRecord {
  std::string location;
  FileRecord file;
  std::string version;  // the map expansion's own version
};

// inputs: the release the dataset was generated from.
struct ManifestInputs {
  // The release's folder, relative to the dataset's folder when generate wrote it (so a dataset
  // and its release move together): use release_folder() to find it.
  std::string dataroot;
  std::string version;
  std::vector<FileRecord> tables;
  std::vector<MapExpansionRecord> map_expansion;  // manifest (plan) order
  std::optional<FileRecord> detections;           // null: vehicles from annotations
  // The record of `location`; nullptr when the manifest has none.
  const MapExpansionRecord* map_of(const std::string& location) const;
};

// An entry of `shards` (a split shard) or of `ladder.shards` (a rung shard).
struct ShardEntry {
  std::string name;      // "test-000000", "test-r1-000000"
  std::string split;     // train, val or test
  std::string location;  // one location per shard
  int64_t tiles = 0;
  std::string first_key, last_key;
  std::string file;    // tar layout: the shard's tar, relative to the dataset
  std::string folder;  // folder layout: its tiles' folder, relative to the dataset
  std::string sha256;  // of the tar, or the digest over the folder's files
  int64_t bytes = 0;   // of the tar, or of the folder's files
  int rung = 0;        // a rung shard's rung (scenes, 1 … kMaxRung); 0 = a split shard
  // file (tar layout) or folder (folder layout).
  const std::string& path() const { return file.empty() ? folder : file; }
};

// Tiles and shards of a split (counts.<split>) or of a rung (ladder.counts.<rung>).
struct TileShardCount {
  int64_t tiles = 0, shards = 0;
};

// counts.
struct ManifestCounts {
  TileShardCount train, val, test;
  int64_t total_tiles = 0;
  // The count of split `name` (train, val, test); nullptr for another name.
  const TileShardCount* of(const std::string& split) const;
};

// ladder (generate --ladder).
struct Ladder {
  std::vector<int> rungs;  // as configured, ascending; kRungAll for "all"
  std::string order;       // time | seeded
  std::vector<std::string> splits;
  std::vector<std::pair<int, TileShardCount>> counts;  // per built rung, ascending
  std::vector<ShardEntry> shards;                      // each with rung >= 1
};

// A region of a location: every tile inside belongs to `split` (docs/dataset-format.md
// "Splits, regions and buffers").
struct Region {
  std::string name, split;
  std::array<double, 4> bounds_m{};  // x_west, y_south, x_east, y_north
};

// A location's planned shard (locations[].shards and rung_shards: no file yet).
struct PlannedShardEntry {
  std::string name, split;
  int rung = 0;  // rung_shards only
  int64_t tiles = 0;
  std::string first_key, last_key;
};

// A location's tiles per split (locations[].counts).
struct SplitTiles {
  int64_t train = 0, val = 0, test = 0;
};

struct LaneGraphCounts {
  int64_t nodes = 0, edges = 0, lanes = 0, map_defects = 0;
};

// A scene of the release the config's scenes.exclude left out.
struct ExcludedScene {
  std::string name;
  std::string location;  // excluded_scenes only (a location's own list omits it)
  std::string reason;
};

struct LocationScenes {
  int64_t used = 0;
  std::vector<ExcludedScene> excluded;
};

// locations[]: one location's plan.
struct ManifestLocation {
  std::string name;
  std::string map_version;
  LaneGraphCounts lane_graph;
  std::optional<LocationScenes> scenes;  // optional within v1
  std::vector<Region> regions;           // manifest order
  SplitTiles counts;                     // tiles per split
  std::vector<PlannedShardEntry> shards, rung_shards;
  // splits.preset before-after only: the time split's figures, kept as written (no reader
  // of a dataset uses them; docs/generating.md).
  nlohmann::ordered_json time_split;
  // splits.preset map-update only: its date, the prior map and the lanes by change label,
  // kept as written (docs/generating.md "Map update").
  nlohmann::ordered_json map_update;
};

enum class Layout { kTar, kFolder };

struct Manifest {
  std::string schema_version = "1";
  // Kept as written: nothing reads them but the schema check (validate manifest.schema),
  // which also says when they are missing. Null when absent.
  nlohmann::ordered_json tool, licence, georeference;
  uint64_t seed = 0;
  // The run's resolved config: its own typed reader is pipeline::config_from_json.
  nlohmann::ordered_json config;
  ManifestInputs inputs;
  Layout layout = Layout::kTar;
  TileFormat tile_format;
  std::vector<ManifestLocation> locations;
  std::optional<std::vector<ExcludedScene>> excluded_scenes;  // optional within v1
  ManifestCounts counts;
  std::vector<ShardEntry> shards;
  std::vector<FileRecord> maps;
  std::optional<Ladder> ladder;

  bool tar_layout() const { return layout == Layout::kTar; }
  // The location named `name`; nullptr when the manifest has none.
  const ManifestLocation* location(const std::string& name) const;
};

// ---- the reader -----------------------------------------------------------------------------

// The text of the manifest at `path`, its size bounded (kMaxManifestBytes) before it is
// read. IoError naming it when missing or unreadable.
std::string read_manifest_text(const std::filesystem::path& path);
// The strict parse of a manifest's text (kMaxManifestDepth, repeated keys refused):
// validate's schema check reads this document.
nlohmann::json parse_manifest_text(std::string_view text, const std::string& file);

// The manifest at `path`: its size bounded before it is read (kMaxManifestBytes), parsed
// strictly (nesting, repeated keys), then manifest_from_json. IoError (missing,
// unreadable) or ParseError naming the file.
Manifest read_manifest(const std::filesystem::path& path);

// `text` as the manifest `file`: the strict parse, then manifest_from_json.
Manifest manifest_from_text(std::string_view text, const std::string& file);

// Every field the model holds, checked: ParseError naming `file`, the JSON pointer
// ("/shards/3/bytes") and what was expected for a missing or mistyped field, a value out of
// its range, or a field the layout needs missing (a tar-layout shard without `file`, a
// shard whose name is not of its split or rung).
Manifest manifest_from_json(const nlohmann::ordered_json& doc, const std::string& file);
Manifest manifest_from_json(const nlohmann::json& doc, const std::string& file);

// The plan's locations as merge reads them from a done-record (the manifest's
// `locations`), checked as the manifest's are; `at` is their JSON pointer there.
std::vector<ManifestLocation> manifest_locations_from_json(const nlohmann::ordered_json& locations,
                                                           const std::string& file, const std::string& at);

// A region {name, split, bounds_m}, its bounds through io/tile_meta.h's bounds_from_json.
Region region_from_json(const nlohmann::ordered_json& region, const std::string& file, const std::string& at);

// ---- the writer -----------------------------------------------------------------------------

// The document merge writes: fields in the schema's order, absent optional parts left
// out; manifest_text is its bytes (1-space indent, a final newline). Reading the text back
// gives `manifest` again.
// The release a dataset at `dataset_root` was generated from: inputs.dataroot resolved against
// the dataset's folder (nsg::resolve_document_path).
std::filesystem::path release_folder(const ManifestInputs& inputs, const std::filesystem::path& dataset_root);

nlohmann::ordered_json manifest_to_json(const Manifest& manifest);
std::string manifest_text(const Manifest& manifest);

// {name, split, bounds_m}: the manifest's record of a region (generate writes it).
nlohmann::ordered_json region_to_json(const Region& region);
// A location's plan as generate records it (the manifest's locations[]).
nlohmann::ordered_json location_to_json(const ManifestLocation& location);

}  // namespace nsg::io
