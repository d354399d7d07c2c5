#include "outputs.h"

#include <algorithm>
#include <set>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/log.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/core/version.h"
#include "nsg/geometry/georef.h"
#include "nsg/graph/geojson.h"
#include "nsg/io/manifest.h"
#include "nsg/io/tar.h"
#include "nsg/nuscenes/database.h"
#include "nsg/pipeline/tile_files.h"

namespace nsg::pipeline {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

namespace {
void remove_stale_temps(const fs::path& target);
}  // namespace

fs::path done_record_path(const fs::path& out, const ShareSpec& share) {
  return out / "parts" / strprintf("share-%06d-of-%06d.json", share.index, share.count);
}

// The config's identity: its JSON with the release's folder absolute and resolved, so
// `--dataroot ../release`, `--dataroot /data/release` and a link to it are one config — a
// rerun from another folder resumes instead of meeting "another config".
std::string config_digest(const GenerateConfig& config) {
  GenerateConfig same = config;
  std::error_code ec;
  if (!same.dataroot.empty()) {
    const fs::path resolved = fs::weakly_canonical(fs::absolute(same.dataroot, ec), ec);
    if (!ec) same.dataroot = resolved.string();
  }
  return sha256_hex(config_to_json(same).dump());
}

std::string item_digest(const std::vector<DoneFile>& files) {
  if (files.size() == 1) return files[0].sha256;
  std::string lines;
  for (const DoneFile& f : files) lines += f.file + '\0' + f.sha256 + "\n";
  return sha256_hex(lines);
}

nlohmann::ordered_json data_licence_json() {
  return {{"name", "CC BY-NC-SA 4.0"},
          {"url", "https://creativecommons.org/licenses/by-nc-sa/4.0/"},
          {"source", "nuScenes"}};
}

std::string data_licence_line() {
  const nlohmann::ordered_json l = data_licence_json();
  return "a dataset built from " + l["source"].get<std::string>() + " inherits its licence, " +
         l["name"].get<std::string>() + " (" + l["url"].get<std::string>() +
         "): non-commercial, share-alike, with attribution; manifest.json records it";
}

namespace {

// The entries a dataset of ours consists of; --overwrite removes files in these only, and
// only those its manifest or share records list.
const std::vector<std::string> kDatasetEntries = {"manifest.json", "shards", "tiles", "maps", "parts"};

}  // namespace

std::set<std::string> dataset_files_listed(const fs::path& out) {
  std::set<std::string> listed;
  std::error_code ec;
  if (fs::is_directory(fs::symlink_status(out / "parts", ec)))
    for (const auto& e : fs::directory_iterator(out / "parts", ec)) {
      const std::string name = e.path().filename().string();
      if (!starts_with(name, "share-") || !ends_with(name, ".json")) continue;
      // A record of ours is a file we wrote, never a link (which could list anything).
      if (!fs::is_regular_file(fs::symlink_status(e.path(), ec))) continue;
      try {
        const DoneRecord record = read_done_record(e.path());
        listed.insert("parts/" + name);
        for (const DoneItem& item : record.items)
          for (const DoneFile& f : item.files) listed.insert(f.file);
      } catch (const Error&) {
        // Unreadable: it lists nothing, so the files are refused, not removed.
      }
    }
  // Ours: a manifest its one reader accepts (a frames export's, or anything else, is not).
  if (fs::is_regular_file(fs::symlink_status(out / "manifest.json", ec))) try {
      const io::Manifest manifest = io::read_manifest(out / "manifest.json");
      listed.insert("manifest.json");
      for (const io::ShardEntry& shard : manifest.shards)
        if (!shard.file.empty()) listed.insert(shard.file);
      if (manifest.ladder)
        for (const io::ShardEntry& shard : manifest.ladder->shards)
          if (!shard.file.empty()) listed.insert(shard.file);
      for (const io::FileRecord& map : manifest.maps) listed.insert(map.file);
    } catch (const Error&) {
      // Unreadable: it lists nothing, so the files are refused, not removed.
    }
  return listed;
}

int64_t remove_our_dataset(const fs::path& out, const std::string& option) {
  const OutputFolder folder(out, option);
  return folder.remove_listed(dataset_files_listed(out), kDatasetEntries,
                              "the dataset's manifest.json or its parts/share-*.json records");
}

namespace {

// Why `out` holds a dataset this run must not mix with ("" = none).
std::string older_dataset(const fs::path& out, const std::string& digest) {
  bool records = false;
  if (fs::is_directory(out / "parts"))
    for (const auto& e : fs::directory_iterator(out / "parts")) {
      const std::string name = e.path().filename().string();
      if (!starts_with(name, "share-") || !ends_with(name, ".json")) continue;
      records = true;
      std::string recorded;
      try {
        recorded = read_done_record(e.path()).config_sha256;
      } catch (const Error&) {
        recorded = "";  // unreadable: of unknown config
      }
      if (recorded != digest)
        return e.path().string() + " records another config (config_sha256 " +
               (recorded.empty() ? std::string("unreadable") : recorded.substr(0, 12)) + "…)";
    }
  if (records) return "";
  for (const char* entry : {"manifest.json", "shards", "tiles"}) {
    const fs::path p = out / entry;
    const bool empty_folder = fs::is_directory(p) && fs::is_empty(p);
    if (fs::exists(p) && !empty_folder) return p.string() + " is there without a share record of this config";
  }
  return "";
}

}  // namespace

void prepare_output_folder(const fs::path& out, const GenerateConfig& config, const ShareSpec& share, bool overwrite) {
  refuse_out_over_input(out, config.dataroot, "--dataroot");  // the release is never the dataset's folder
  if (!fs::is_directory(out)) return;
  if (overwrite) {
    // Concurrent shares would delete each other's work.
    NSG_CHECK(share.count == 1, ConfigError, out.string(), "--overwrite",
              "a one-share run (remove the old dataset before starting " + std::to_string(share.count) + " shares)");
    const int64_t removed = remove_our_dataset(out, "--overwrite");
    if (removed > 0)
      log::info("generate: --overwrite: removed the " + std::to_string(removed) + " file(s) of the dataset in " +
                out.string());
    return;
  }
  const std::string why = older_dataset(out, config_digest(config));
  NSG_CHECK(why.empty(), ConfigError, out.string(), "--out",
            "an empty folder or one holding this config's dataset: it holds an older dataset (" + why +
                "); --overwrite removes it first");
}

bool verify_item(const fs::path& out, const DoneItem& item, std::string* why) {
  if (item.files.empty()) {
    *why = "the record lists no files";
    return false;
  }
  for (const DoneFile& f : item.files) {
    const fs::path path = out / f.file;
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec) {
      *why = path.string() + " is missing";
      return false;
    }
    if (size != static_cast<uintmax_t>(f.bytes) || sha256_file(path) != f.sha256) {
      *why = path.string() + " does not match its recorded sha256/size (corrupt or changed)";
      return false;
    }
  }
  return true;
}

OutputWriter::OutputWriter(fs::path out, const GenerateConfig& config, ShareSpec share)
    : out_(std::move(out)), folder_(out_), config_(config), share_(share), config_digest_(config_digest(config)) {
  std::error_code ec;
  fs::create_directories(out_ / "parts", ec);
  if (ec) throw IoError(out_.string(), "", "a writable output folder (" + ec.message() + ")");
  const fs::path record = done_record_path(out_, share_);
  remove_stale_temps(record);  // a record being rewritten when the last run was killed
  if (!fs::exists(record)) return;
  try {
    const DoneRecord old = read_done_record(record);
    if (old.config_sha256 != config_digest_) return;  // another config: redo everything
    for (const DoneItem& item : old.items) previous_[item.id] = item;
  } catch (const Error&) {
    // A damaged record is not trusted: every item is redone.
  }
}

std::string OutputWriter::shard_item_id(const PlannedShard& shard) const {
  return config_.output.layout == Layout::kTar ? "shards/" + shard.name + ".tar" : "tiles/" + shard.name;
}

bool OutputWriter::verified(const std::string& id) {
  auto it = previous_.find(id);
  if (it == previous_.end()) return false;
  std::string why;
  if (!verify_item(out_, it->second, &why)) return false;
  for (const DoneFile& f : it->second.files) remove_stale_temps(out_ / f.file);
  items_.push_back(it->second);
  save(false);
  return true;
}

void OutputWriter::add_plan(ordered_json location_plan) { plans_.push_back(std::move(location_plan)); }

namespace {

// Temp files a killed run left for `target` ("<target>.tmp-<pid>-<n>"). Only the share
// that owns the target removes them, so a live share's temp files are never touched.
void remove_stale_temps(const fs::path& target) {
  std::error_code ec;
  const fs::path dir = target.parent_path();
  if (!fs::is_directory(dir, ec)) return;
  const std::string prefix = target.filename().string() + ".tmp-";
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().filename().string().rfind(prefix, 0) == 0) fs::remove(e.path(), ec);
}

DoneFile file_entry(const fs::path& out, const std::string& relative) {
  const fs::path path = out / relative;
  return {relative, sha256_file(path), static_cast<int64_t>(fs::file_size(path))};
}

ordered_json lonlat_ring(const std::string& location, const tiling::RectM& r) {
  ordered_json ring = ordered_json::array();
  const double xs[5] = {r.x_west_m, r.x_east_m, r.x_east_m, r.x_west_m, r.x_west_m};
  const double ys[5] = {r.y_south_m, r.y_south_m, r.y_north_m, r.y_north_m, r.y_south_m};
  for (int i = 0; i < 5; ++i) {
    const geometry::LonLat p = geometry::map_to_lonlat(location, xs[i], ys[i]);
    ring.push_back({p.lon_deg, p.lat_deg});
  }
  return ordered_json::array({ring});
}

ordered_json polygon_feature(const std::string& location, const tiling::RectM& r, ordered_json properties) {
  return {{"type", "Feature"},
          {"properties", std::move(properties)},
          {"geometry", {{"type", "Polygon"}, {"coordinates", lonlat_ring(location, r)}}}};
}

std::string regions_geojson(const LocationPlan& plan, double resolution_m, int size_px) {
  ordered_json features = ordered_json::array();
  for (const tiling::Region& r : plan.regions)
    features.push_back(polygon_feature(
        plan.location, r.bounds,
        {{"kind", "region"},
         {"name", r.name},
         {"split", r.split},
         {"bounds_m", {r.bounds.x_west_m, r.bounds.y_south_m, r.bounds.x_east_m, r.bounds.y_north_m}}}));
  for (size_t i = 0; i < plan.crops.size(); ++i) {
    const tiling::Crop& c = plan.crops[i];
    features.push_back(polygon_feature(plan.location, c.bounds(resolution_m, size_px),
                                       {{"kind", "crop"},
                                        {"key", plan.keys[i]},
                                        {"split", c.split},
                                        {"region", c.region},
                                        {"lidar_coverage", c.lidar_coverage}}));
  }
  const ordered_json doc = {
      {"type", "FeatureCollection"}, {"name", plan.location + " split regions and crops"}, {"features", features}};
  return doc.dump(1) + "\n";
}

}  // namespace

std::vector<std::string> scene_names(const nuscenes::Database& db, const std::vector<int32_t>& sweeps) {
  std::set<nuscenes::Index> scenes;
  for (int32_t sd : sweeps) scenes.insert(db.sample[db.sample_data[sd].sample].scene);
  std::vector<std::string> names;
  for (nuscenes::Index s : scenes) names.push_back(db.scene[s].name);
  return names;
}

void OutputWriter::write_maps(const std::string& id, const std::string& location, const graph::LaneGraph& graph,
                              const LocationPlan& plan) {
  const std::string lanes = "maps/" + location + "/lanes.geojson";
  const std::string regions = "maps/" + location + "/regions.geojson";
  remove_stale_temps(out_ / lanes);
  remove_stale_temps(out_ / regions);
  graph::write_geojson_file(graph, location, folder_.prepare(lanes).string());
  write_file_atomic(folder_.prepare(regions), regions_geojson(plan, config_.resolution_m, config_.crops.size_px));
  DoneItem item;
  item.id = id;
  item.kind = "maps";
  item.location = location;
  item.files = {file_entry(out_, lanes), file_entry(out_, regions)};
  record_item(std::move(item));
}

size_t OutputWriter::write_shard(const std::string& id, const nuscenes::Database& db, const LocationPlan& plan,
                                 const PlannedShard& shard, const tiling::LocationRasters& layers,
                                 const GenerateRun& run, Progress* progress) {
  return write_tiles(
      id, shard, plan.location, shard.split,
      [&](size_t i) {
        const tiling::Tile tile = tiling::extract_tile(layers, plan.location, plan.crops[i], plan.keys[i],
                                                       config_.resolution_m, config_.crops.size_px);
        TileFileOptions options;
        options.deflate_level = config_.output.deflate_level;
        options.scenes = scene_names(db, tile.sweeps);
        return encode_tile_files(tile, options);
      },
      run, progress);
}

size_t OutputWriter::write_tiles(const std::string& id, const PlannedShard& shard, const std::string& location,
                                 const std::string& folder, const std::function<std::vector<TileFile>(size_t)>& encode,
                                 const GenerateRun& run, Progress* progress) {
  const bool tar = config_.output.layout == Layout::kTar;
  std::unique_ptr<io::TarWriter> writer;
  if (tar) {
    remove_stale_temps(out_ / id);
    writer = std::make_unique<io::TarWriter>(folder_.prepare(id));
  }
  std::vector<DoneFile> files;
  // Tiles are cut and encoded in parallel batches and written in key order, so memory
  // stays at one batch and the bytes do not depend on the thread count.
  const size_t batch = static_cast<size_t>(std::max(8, 4 * resolve_threads(run.threads)));
  for (size_t b = shard.first; b < shard.first + shard.count; b += batch) {
    const size_t n = std::min(batch, shard.first + shard.count - b);
    std::vector<std::vector<TileFile>> encoded(n);
    parallel_for(n, run.threads, [&](size_t k) { encoded[k] = encode(b + k); });
    for (size_t k = 0; k < n; ++k) {
      for (const TileFile& f : encoded[k]) {
        bytes_written_ += f.bytes.size();
        if (tar) {
          writer->add(f.name, f.bytes);
        } else {
          const std::string key = f.name.substr(0, f.name.find('.'));
          const std::string relative = "tiles/" + folder + "/" + key + "/" + f.name;
          remove_stale_temps(out_ / relative);
          write_file_atomic(folder_.prepare(relative),
                            std::string_view(reinterpret_cast<const char*>(f.bytes.data()), f.bytes.size()));
          files.push_back({relative,
                           sha256_hex(std::string_view(reinterpret_cast<const char*>(f.bytes.data()), f.bytes.size())),
                           static_cast<int64_t>(f.bytes.size())});
        }
      }
      if (progress) {
        progress->set_detail(strprintf("%.1f MB written", static_cast<double>(bytes_written_) / 1e6));
        progress->advance();
      }
    }
  }
  if (tar) {
    const io::TarWriter::Result r = writer->finish();
    files.push_back({id, r.sha256_hex, static_cast<int64_t>(r.bytes)});
  }
  DoneItem item;
  item.id = id;
  item.kind = "shard";
  item.location = location;
  item.split = shard.split;
  item.shard = shard.name;
  item.tiles = static_cast<int64_t>(shard.count);
  item.files = std::move(files);
  record_item(std::move(item));
  return shard.count;
}

void OutputWriter::record_item(DoneItem item) {
  item.digest = item_digest(item.files);
  for (DoneItem& existing : items_)
    if (existing.id == item.id) {
      existing = std::move(item);
      save(false);
      return;
    }
  items_.push_back(std::move(item));
  save(false);
}

void OutputWriter::save(bool complete) {
  DoneRecord record;
  record.tool_version = kVersion;
  record.share_index = share_.index;
  record.share_count = share_.count;
  record.config_sha256 = config_digest_;
  record.config_json = config_to_json(config_);
  record.complete = complete;
  record.plan_json = complete ? plans_ : ordered_json::array();
  record.items = items_;
  write_file_atomic(folder_.prepare(done_record_path({}, share_).generic_string()), done_record_text(record));
}

void OutputWriter::finish() { save(true); }

}  // namespace nsg::pipeline
