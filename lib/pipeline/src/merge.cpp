// `merge`: checks that every share of a run finished and that every output still hashes
// as recorded, then writes manifest.json (docs/dataset-format.md).
#include <algorithm>
#include <map>
#include <regex>
#include <set>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/log.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/core/version.h"
#include "nsg/geometry/georef.h"
#include "nsg/io/manifest.h"
#include "nsg/pipeline/generate.h"
#include "nsg/pipeline/tile_files.h"
#include "outputs.h"

namespace nsg::pipeline {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

namespace {

// Every done-record in out/parts, each through its one reader (pipeline/done_record.h),
// ordered by share count then index. A record whose name and `share` disagree is refused.
std::vector<DoneRecord> read_records(const fs::path& out) {
  const fs::path parts = out / "parts";
  if (!fs::is_directory(parts))
    throw IoError(parts.string(), "", "the done-records of a generate run (no parts/ folder: did generate run here?)");
  static const std::regex kName(R"(share-(\d{6})-of-(\d{6})\.json)");
  std::vector<DoneRecord> records;
  for (const auto& entry : fs::directory_iterator(parts)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (!std::regex_match(name, m, kName)) continue;
    DoneRecord r = read_done_record(entry.path());
    NSG_CHECK(r.share_index == std::stoi(m[1]) && r.share_count == std::stoi(m[2]), ParseError, entry.path().string(),
              "/share", "the share its name says (" + std::string(m[1]) + " of " + std::string(m[2]) + ")");
    records.push_back(std::move(r));
  }
  std::sort(records.begin(), records.end(), [](const DoneRecord& a, const DoneRecord& b) {
    return a.share_count != b.share_count ? a.share_count < b.share_count : a.share_index < b.share_index;
  });
  return records;
}

// The share count of the run to merge: that of the newest done-record, so that records a
// run with another share count left behind are the older dataset.
int run_share_count(const std::vector<DoneRecord>& records) {
  const DoneRecord* newest = &records.front();
  auto newest_time = fs::last_write_time(newest->path);
  for (const DoneRecord& r : records) {
    const auto t = fs::last_write_time(r.path);
    if (t > newest_time) newest = &r, newest_time = t;
  }
  return newest->share_count;
}

// Files under the dataset's folders that none of the run's shares recorded, and a
// manifest.json written for another config: what an older dataset left behind. The
// folders are walked without following links (a linked maps/ is refused, not entered).
std::vector<fs::path> older_dataset_files(const fs::path& out, const std::map<int, const DoneRecord*>& shares,
                                          const GenerateConfig& config) {
  std::set<std::string> recorded;
  for (const auto& [index, record] : shares)
    for (const DoneItem& item : record->items)
      for (const DoneFile& f : item.files) recorded.insert(f.file);
  std::vector<fs::path> leftovers;
  for (const std::string& f : OutputFolder(out, "merge").files_under({"shards", "tiles", "maps"}))
    if (!recorded.count(f)) leftovers.push_back(out / f);
  const fs::path manifest = out / "manifest.json";
  if (fs::exists(manifest)) {
    bool this_config = false;
    try {
      // One config however its release was spelled (config_digest).
      const io::Manifest m = io::read_manifest(manifest);
      this_config =
          config_digest(config_from_json(json(m.config), manifest.string() + ":/config")) == config_digest(config);
    } catch (const Error&) {
      this_config = false;  // unreadable: not this run's
    }
    if (!this_config) leftovers.insert(leftovers.begin(), manifest);
  }
  return leftovers;
}

// Removes `files` (each one a document of ours lists: `ours`, read before anything was
// removed) and the tile folders they leave empty; refuses, removing nothing, when any
// other file is among them.
void remove_leftovers(const fs::path& out, const std::vector<fs::path>& files, const std::set<std::string>& ours) {
  std::vector<std::string> foreign;
  for (const fs::path& f : files) {
    const std::string relative = f.lexically_relative(out).generic_string();
    if (!ours.count(relative) && !is_temp_name(f.filename().string())) foreign.push_back(printable_text(relative));
  }
  NSG_CHECK(foreign.empty(), ConfigError, out.string(), "--overwrite",
            "files an older dataset of ours lists (its manifest.json or parts/ records); " +
                std::to_string(foreign.size()) + " file(s) no document of ours lists, e.g. " + foreign.front() +
                ": nsgraph removes only files it wrote; move them away");
  for (const fs::path& f : files) {
    std::error_code ec;
    if (!fs::is_regular_file(fs::symlink_status(f, ec))) continue;
    fs::remove(f, ec);
    for (fs::path dir = f.parent_path(); dir != out && fs::is_empty(dir, ec); dir = dir.parent_path())
      fs::remove(dir, ec);
  }
  if (!files.empty())
    log::info("merge: --overwrite: removed " + std::to_string(files.size()) + " file(s) of an older dataset in " +
              out.string());
}

io::FileRecord input_file(const fs::path& root, const fs::path& path) {
  return {fs::relative(path, root).generic_string(), sha256_file(path), static_cast<int64_t>(fs::file_size(path))};
}

// `out`: the dataset's folder, which inputs.dataroot is written relative to.
io::ManifestInputs inputs_of(const fs::path& out, const ordered_json& config,
                             const std::vector<io::ManifestLocation>& plan) {
  io::ManifestInputs in;
  const fs::path root = config["dataroot"].get<std::string>();
  in.dataroot = path_relative_to(root, out);
  in.version = config["version"].get<std::string>();
  std::vector<fs::path> table_files;
  for (const auto& e : fs::directory_iterator(root / in.version))
    if (e.path().extension() == ".json") table_files.push_back(e.path());
  std::sort(table_files.begin(), table_files.end());
  for (const fs::path& p : table_files) in.tables.push_back(input_file(root, p));
  for (const io::ManifestLocation& location : plan)
    in.map_expansion.push_back({location.name,
                                input_file(root, root / "maps" / "expansion" / (location.name + ".json")),
                                location.map_version});
  const std::string detections = config["vehicles"]["detections"].get<std::string>();
  if (!detections.empty()) in.detections = input_file(root, detections);
  return in;
}

ordered_json georeference_json(const std::vector<io::ManifestLocation>& plan) {
  ordered_json locations = ordered_json::object();
  for (const io::ManifestLocation& location : plan) {
    const std::string& name = location.name;
    const geometry::LocationInfo& info = geometry::location_info(name);
    locations[name] = {{"origin_lat_deg", info.origin_lat_deg},
                       {"origin_lon_deg", info.origin_lon_deg},
                       {"proj", geometry::aeqd_proj_string(name)}};
  }
  return {{"frame", "map metres east (x) and north (y) of each location's south-west corner"},
          {"projection",
           "the devkit's: azimuthal equidistant on a sphere of radius 6378137 m about the origin; GeoTIFFs carry it "
           "as a user-defined CRS, GeoJSON is WGS 84 lon/lat"},
          {"note", "nuScenes does not guarantee that its maps align with GPS coordinates"},
          {"locations", locations}};
}

}  // namespace

namespace {

// The shares of the run to merge (that of the newest record), by index. Records of a run with
// another share count are an older run's: refused, or removed with --overwrite. DataError
// naming every share missing or unfinished.
std::map<int, const DoneRecord*> finished_shares(const fs::path& out, const std::vector<DoneRecord>& all, int count,
                                                 bool overwrite, std::vector<fs::path>* other_runs) {
  std::vector<std::string> problems;
  std::map<int, const DoneRecord*> shares;
  for (const DoneRecord& r : all) {
    if (r.share_count != count) {
      other_runs->push_back(r.path);
      problems.push_back(r.path.string() + ": a record of a " + std::to_string(r.share_count) +
                         "-share run next to a " + std::to_string(count) +
                         "-share run (an older run's; --overwrite removes it)");
      continue;
    }
    shares[r.share_index] = &r;
  }
  if (overwrite) problems.clear();  // their records are removed with the older dataset's files
  for (int i = 0; i < count; ++i) {
    auto it = shares.find(i);
    if (it == shares.end())
      problems.push_back(strprintf("share %d of %d: missing (no parts/share-%06d-of-%06d.json)", i, count, i, count));
    else if (!it->second->complete) problems.push_back(strprintf("share %d of %d: not finished (rerun it)", i, count));
  }
  if (!problems.empty()) throw DataError(out.string(), "merge", "every share finished:\n  " + join(problems, "\n  "));
  return shares;
}

using ItemsById = std::map<std::string, std::pair<const DoneItem*, int>>;  // id → item, share

// Every share's items by id; a share that ran with another config or plan than share 0 is
// added to `problems`.
ItemsById items_by_id(const std::map<int, const DoneRecord*>& shares, int count, std::vector<std::string>& problems) {
  const DoneRecord& first = *shares.at(0);
  ItemsById items;
  for (const auto& [index, record] : shares) {
    if (record->config_sha256 != first.config_sha256 || record->plan_json != first.plan_json)
      problems.push_back(strprintf("share %d of %d: ran with another config or plan than share 0", index, count));
    for (const DoneItem& item : record->items) items[item.id] = {&item, index};
  }
  return items;
}

// The recorded item `id` when it verifies on disk; otherwise nullptr, with the reason added
// to `problems`.
const DoneItem* verified_item(const fs::path& out, const ItemsById& items, const std::string& id,
                              std::vector<std::string>& problems) {
  auto it = items.find(id);
  if (it == items.end()) {
    problems.push_back(id + ": missing from every done-record");
    return nullptr;
  }
  std::string why;
  if (!verify_item(out, *it->second.first, &why)) {
    problems.push_back(id + " (share " + std::to_string(it->second.second) + "): " + why);
    return nullptr;
  }
  return it->second.first;
}

// A shard's manifest entry: its plan fields, then the tar's file or the folder's digest and bytes.
io::ShardEntry shard_entry(const io::ManifestLocation& location, const io::PlannedShardEntry& shard,
                           const DoneItem& item, bool tar) {
  io::ShardEntry entry;
  entry.name = shard.name;
  entry.split = shard.split;
  entry.location = location.name;
  entry.tiles = shard.tiles;
  entry.first_key = shard.first_key;
  entry.last_key = shard.last_key;
  entry.rung = shard.rung;
  if (tar) {
    entry.file = item.files.at(0).file;
    entry.sha256 = item.files.at(0).sha256;
    entry.bytes = item.files.at(0).bytes;
  } else {
    entry.folder = "tiles/" + (shard.rung > 0 ? shard.split + "-r" + std::to_string(shard.rung) : shard.split);
    entry.sha256 = item.digest;
    for (const DoneFile& f : item.files) entry.bytes += f.bytes;
  }
  return entry;
}

// The manifest's shard and map entries, in plan order, and each split's and rung's tile and
// shard counts.
struct PlannedOutputs {
  std::vector<io::ShardEntry> shards;
  std::vector<io::FileRecord> maps;
  std::map<std::string, io::TileShardCount> per_split;
  std::vector<io::ShardEntry> rung_shards;  // the ladder's (generate --ladder)
  std::map<int, io::TileShardCount> per_rung;
};

// Every planned item, in plan order, must be recorded and verify on disk; those that do not
// are added to `problems`.
PlannedOutputs planned_outputs(const fs::path& out, const std::vector<io::ManifestLocation>& plan,
                               const ItemsById& items, bool tar, std::vector<std::string>& problems) {
  PlannedOutputs o;
  const auto item_of = [&](const io::PlannedShardEntry& shard) {
    return verified_item(out, items, tar ? "shards/" + shard.name + ".tar" : "tiles/" + shard.name, problems);
  };
  for (const io::ManifestLocation& location : plan) {
    if (const DoneItem* item = verified_item(out, items, "maps/" + location.name, problems))
      for (const DoneFile& f : item->files) o.maps.push_back({f.file, f.sha256, f.bytes});
    for (const io::PlannedShardEntry& shard : location.shards) {
      const DoneItem* item = item_of(shard);
      if (item == nullptr) continue;
      o.per_split[shard.split].tiles += shard.tiles;
      ++o.per_split[shard.split].shards;
      o.shards.push_back(shard_entry(location, shard, *item, tar));
    }
    for (const io::PlannedShardEntry& shard : location.rung_shards) {
      const DoneItem* item = item_of(shard);
      if (item == nullptr) continue;
      o.per_rung[shard.rung].tiles += shard.tiles;
      ++o.per_rung[shard.rung].shards;
      o.rung_shards.push_back(shard_entry(location, shard, *item, tar));
    }
  }
  return o;
}

// The manifest's "ladder": the config's rungs, which splits have them, tiles and shards per
// built rung and the rung shards (docs/dataset-format.md). Absent without a ladder.
io::Ladder ladder_of(const ordered_json& config, const PlannedOutputs& o) {
  const ordered_json& ladder = config["ladder"];
  io::Ladder l;
  for (const auto& rung : ladder["rungs"]) l.rungs.push_back(rung.is_string() ? io::kRungAll : rung.get<int>());
  l.order = ladder["order"].get<std::string>();
  l.splits = ladder["splits"].get<std::vector<std::string>>();
  l.counts.assign(o.per_rung.begin(), o.per_rung.end());  // ascending rungs
  l.shards = o.rung_shards;
  return l;
}

// Files an older dataset left in `out` (and the records of other runs, `other_runs`):
// refused, or removed with --overwrite — all checked before any is removed.
void clear_older_dataset(const fs::path& out, const std::map<int, const DoneRecord*>& shares,
                         const GenerateConfig& config, bool overwrite, const std::set<std::string>& ours,
                         const std::vector<fs::path>& other_runs) {
  std::vector<fs::path> leftovers = older_dataset_files(out, shares, config);
  leftovers.insert(leftovers.end(), other_runs.begin(), other_runs.end());
  if (leftovers.empty()) return;
  NSG_CHECK(overwrite, DataError, out.string(), "merge",
            "a folder holding only this run's dataset: " + std::to_string(leftovers.size()) +
                " file(s) no share of it recorded, e.g. " + leftovers.front().string() +
                " (left from an older dataset; --overwrite removes them)");
  remove_leftovers(out, leftovers, ours);
}

// Tiles and shards per split, and the total; warns when there are no tiles.
io::ManifestCounts counts_of(const fs::path& out, PlannedOutputs& o) {
  io::ManifestCounts counts{o.per_split["train"], o.per_split["val"], o.per_split["test"], 0};
  counts.total_tiles = counts.train.tiles + counts.val.tiles + counts.test.tiles;
  if (counts.total_tiles == 0) log::warn("merge: " + out.string() + " holds no tiles (a run with --allow-empty)");
  return counts;
}

std::vector<io::ExcludedScene> excluded_scenes_of(const std::vector<io::ManifestLocation>& plan) {
  std::vector<io::ExcludedScene> excluded;
  for (const io::ManifestLocation& location : plan)
    if (location.scenes)
      for (const io::ExcludedScene& e : location.scenes->excluded)
        excluded.push_back({e.name, location.name, e.reason});
  return excluded;
}

// The manifest of a merged run, written by its one writer (io::manifest_text).
io::Manifest manifest_of(const fs::path& out, const ordered_json& config, std::vector<io::ManifestLocation> plan,
                         bool tar, PlannedOutputs& o) {
  io::Manifest m;
  m.tool = {{"name", "nsgraph"}, {"version", kVersion}};
  m.licence = data_licence_json();
  m.seed = config["seed"].get<uint64_t>();
  m.config = config;
  m.inputs = inputs_of(out, config, plan);
  m.georeference = georeference_json(plan);
  m.layout = tar ? io::Layout::kTar : io::Layout::kFolder;
  m.tile_format = {config["resolution_m"].get<double>(), config["crops"]["size_px"].get<int>(),
                   "<location>-<split>-<NNNNNN>", tile_file_suffixes()};
  m.excluded_scenes = excluded_scenes_of(plan);
  m.locations = std::move(plan);
  m.counts = counts_of(out, o);
  m.shards = o.shards;
  m.maps = o.maps;
  if (config.contains("ladder") && !config["ladder"]["rungs"].empty()) m.ladder = ladder_of(config, o);
  return m;
}

void merge_records(const fs::path& out, bool overwrite) {
  const std::vector<DoneRecord> all = read_records(out);
  if (all.empty()) throw IoError((out / "parts").string(), "", "done-records share-<i>-of-<n>.json");
  const int count = run_share_count(all);
  const std::set<std::string> ours = dataset_files_listed(out);  // before anything is removed
  std::vector<fs::path> other_runs;                              // removed with --overwrite, after every check
  const std::map<int, const DoneRecord*> shares = finished_shares(out, all, count, overwrite, &other_runs);

  const DoneRecord& first = *shares.at(0);
  // The plan is the manifest's `locations` (read as the manifest's reader reads them).
  std::vector<io::ManifestLocation> plan = first.plan;
  const ordered_json& config = first.config_json;
  const bool tar = first.config.output.layout == Layout::kTar;
  std::vector<std::string> problems;
  const ItemsById items = items_by_id(shares, count, problems);
  PlannedOutputs outputs = planned_outputs(out, plan, items, tar, problems);
  if (!problems.empty())
    throw DataError(out.string(), "merge", "every planned output present and intact:\n  " + join(problems, "\n  "));

  clear_older_dataset(out, shares, first.config, overwrite, ours, other_runs);
  write_file_atomic(out / "manifest.json", io::manifest_text(manifest_of(out, config, std::move(plan), tar, outputs)));
}

}  // namespace

void merge(const fs::path& out, bool overwrite) {
  try {
    merge_records(out, overwrite);
  } catch (const json::exception& e) {
    // A field check_record does not cover (the config's and plan's own members) mistyped.
    throw ParseError((out / "parts").string(), "done-records",
                     std::string("the fields generate writes, of their types (") + e.what() + ")");
  }
}

}  // namespace nsg::pipeline
