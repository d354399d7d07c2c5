#include "nsg/pipeline/generate.h"

#include <algorithm>
#include <malloc.h>  // malloc_trim (glibc)

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>

#include <nlohmann/json.hpp>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/log.h"
#include "nsg/core/memory.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/rng.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/geometry/georef.h"
#include "nsg/graph/from_map.h"
#include "nsg/graph/geojson.h"
#include "nsg/graph/map_changes.h"
#include "nsg/graph/segment_index.h"
#include "nsg/io/manifest.h"
#include "nsg/io/tar.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/map_expansion.h"
#include "nsg/pipeline/location_layers.h"
#include "nsg/pipeline/tile_files.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/pipeline/input_checks.h"
#include "nsg/tiling/tile.h"
#include "ladder_tiles.h"
#include "layer_sources.h"
#include "memory_plan.h"
#include "outputs.h"
#include "plan.h"

namespace nsg::pipeline {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

void ShareSpec::validate() const {
  if (count < 1) throw ConfigError("", "--num-shards", "at least 1");
  if (index < 0 || index >= count)
    throw ConfigError("", "--shard-index", "an index in [0, " + std::to_string(count) + ")");
}

namespace {

std::optional<int> env_int(const char* name) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return std::nullopt;
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  if (*end != '\0' || x < 0 || x > 1'000'000) throw ConfigError("", std::string("$") + name, "a non-negative integer");
  return static_cast<int>(x);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

ShareSpec resolve_share(std::optional<int> index, std::optional<int> count) {
  ShareSpec s;
  if (index || count) {
    if (!index || !count) {
      // JOB_COMPLETION_INDEX (Kubernetes Indexed Job) pairs with an explicit count.
      if (count && !index) index = env_int("JOB_COMPLETION_INDEX");
      if (!index || !count) throw ConfigError("", "--shard-index/--num-shards", "both, or neither");
    }
    s = {*index, *count};
  } else if (auto slurm_id = env_int("SLURM_ARRAY_TASK_ID")) {
    auto slurm_count = env_int("SLURM_ARRAY_TASK_COUNT");
    if (!slurm_count) throw ConfigError("", "$SLURM_ARRAY_TASK_COUNT", "set together with SLURM_ARRAY_TASK_ID");
    // Arrays may start at 1 (--array=1-N): SLURM_ARRAY_TASK_MIN says where.
    const int min = env_int("SLURM_ARRAY_TASK_MIN").value_or(0);
    s = {*slurm_id - min, *slurm_count};
  }
  s.validate();
  return s;
}

namespace {

// Everything a location needs while its items run.
struct LocationState {
  LocationPlan plan;
  graph::LaneGraph graph;
  std::unique_ptr<graph::SegmentIndex> index;
  std::vector<LayerSource> sources;  // the layers of every scene, or of each side of the split date
  // splits.preset map-update: the prior map's graph, its index, every lane token's label.
  graph::LaneGraph prior_graph;
  std::unique_ptr<graph::SegmentIndex> prior_index;
  std::map<std::string, graph::MapChange> changes;
};

// splits.prior_maps' file for `location` ("" = the release's maps/prior/expansion).
std::filesystem::path prior_map_file(const GenerateConfig& config, const std::string& location) {
  const std::filesystem::path dir = config.prior_maps.empty()
                                        ? std::filesystem::path(config.dataroot) / "maps" / "prior" / "expansion"
                                        : std::filesystem::path(config.prior_maps);
  return dir / (safe_name(location, dir.string(), "location") + ".json");
}

std::vector<std::string> resolve_locations(const GenerateConfig& config, const nuscenes::Database& db) {
  if (!config.locations.empty()) {
    for (const std::string& l : config.locations) {
      const bool present =
          std::any_of(db.log.begin(), db.log.end(), [&](const nuscenes::Log& g) { return g.location == l; });
      if (!present) throw ConfigError("", "locations", "locations with logs in the release ('" + l + "' has none)");
    }
    return config.locations;
  }
  // Every location with a log, in the devkit's order of the four maps, then others by name.
  std::set<std::string> present;
  for (const nuscenes::Log& g : db.log) present.insert(g.location);
  std::vector<std::string> out;
  for (const geometry::LocationInfo& info : geometry::known_locations())
    if (present.erase(std::string(info.name))) out.emplace_back(info.name);
  out.insert(out.end(), present.begin(), present.end());
  return out;
}

// What the run's LiDAR and camera stages will read, counted from the tables before any
// work starts so their progress lines have totals (and ETAs) from the first update.
struct StageTotals {
  std::map<std::string, size_t> scenes, sweeps, images;  // per location
  uint64_t all_sweeps = 0, all_images = 0;
};

StageTotals count_stage_work(const nuscenes::Database& db, const std::vector<std::string>& locations,
                             const std::string& lidar_channel, const std::vector<char>& excluded) {
  StageTotals t;
  for (const std::string& l : locations) t.scenes[l] = t.sweeps[l] = t.images[l] = 0;
  const auto location_of_scene = [&](nuscenes::Index scene) -> const std::string& {
    return db.log[db.scene[scene].log].location;
  };
  for (nuscenes::Index s = 0; s < static_cast<nuscenes::Index>(db.scene.size()); ++s) {
    if (excluded[static_cast<size_t>(s)]) continue;
    auto it = t.scenes.find(location_of_scene(s));
    if (it != t.scenes.end()) ++it->second;
  }
  for (const nuscenes::SampleData& sd : db.sample_data) {
    const bool lidar = sd.modality == nuscenes::Modality::kLidar && db.channel(sd) == lidar_channel;
    const bool image = sd.modality == nuscenes::Modality::kCamera && sd.is_key_frame;
    if (!lidar && !image) continue;
    const nuscenes::Index scene = db.sample[sd.sample].scene;
    if (excluded[static_cast<size_t>(scene)]) continue;
    std::map<std::string, size_t>& per = lidar ? t.sweeps : t.images;
    auto it = per.find(location_of_scene(scene));
    if (it == per.end()) continue;
    ++it->second;
    ++(lidar ? t.all_sweeps : t.all_images);
  }
  return t;
}

// Marks the scenes of the run's locations that the config leaves out (scenes.exclude) and
// returns them, in scene-table order, with their reasons.
std::vector<std::pair<nuscenes::Index, const ExcludedScene*>> find_excluded_scenes(
    const GenerateConfig& config, const nuscenes::Database& db, const std::vector<std::string>& locations,
    std::vector<char>& excluded) {
  std::map<std::string, const ExcludedScene*> by_name;
  for (const ExcludedScene& e : config.exclude_scenes) by_name[e.name] = &e;
  const std::set<std::string> planned(locations.begin(), locations.end());
  excluded.assign(db.scene.size(), 0);
  std::vector<std::pair<nuscenes::Index, const ExcludedScene*>> out;
  for (nuscenes::Index s = 0; s < static_cast<nuscenes::Index>(db.scene.size()); ++s) {
    auto it = by_name.find(db.scene[s].name);
    if (it == by_name.end() || !planned.count(db.log[db.scene[s].log].location)) continue;
    excluded[static_cast<size_t>(s)] = 1;
    out.emplace_back(s, it->second);
  }
  return out;
}

// Resident memory after a stage, for --verbose runs and for checking the estimate.
void log_memory(const std::string& stage) {
  log::debug(strprintf("generate: memory after %s: %s resident, peak %s", stage.c_str(),
                       human_bytes(static_cast<double>(current_rss_bytes())).c_str(),
                       human_bytes(static_cast<double>(peak_rss_bytes())).c_str()));
}

// A finished (packed) LiDAR layer's bytes per block besides its covered cells: bitmap, row
// counts, vector headers, spare capacity and the block map's node (what the memory plan's
// packed block cost stands for).
size_t packed_block_overhead_bytes(const raster::LidarLayer& lidar) {
  constexpr size_t kMapNodeBytes = 48;  // std::map node: three pointers, colour, key
  const size_t blocks = lidar.cells().block_count();
  if (blocks == 0) return 0;
  const size_t cells = lidar.covered_cells() * sizeof(raster::LidarCell);
  const size_t bytes = lidar.cells().memory_bytes();
  return (bytes > cells ? bytes - cells : 0) / blocks + kMapNodeBytes;
}

// The peak-memory estimate, logged, and refused above --max-memory before any heavy work.
void check_memory(const nuscenes::Database& db, const std::vector<std::string>& locations,
                  const std::vector<char>& excluded, const GenerateConfig& config, const GenerateRun& run) {
  std::map<std::string, std::vector<nuscenes::Index>> scenes;
  for (const std::string& location : locations) scenes[location];
  for (nuscenes::Index s = 0; s < static_cast<nuscenes::Index>(db.scene.size()); ++s) {
    auto it = scenes.find(db.log[db.scene[s].log].location);
    if (it != scenes.end() && !excluded[static_cast<size_t>(s)]) it->second.push_back(s);
  }
  const bool cameras = config.raster.camera.rgb || config.raster.camera.semantic;
  const MemoryEstimate e = estimate_generate_memory(db, scenes, config, run.threads, cameras);
  log::info("generate: estimated peak memory " + e.describe());
  log::debug(strprintf("generate: estimated peak memory in bytes: %llu", static_cast<unsigned long long>(e.total())));
  log::debug("generate: memory plan: " + e.plan_details());
  log::debug(strprintf("generate: memory limit in bytes: %llu%s", static_cast<unsigned long long>(run.max_memory_bytes),
                       run.max_memory_from_machine ? " (the memory available)" : ""));
  if (run.max_memory_bytes == 0 || e.total() <= run.max_memory_bytes) return;
  throw ConfigError("", "--max-memory",
                    "a run that fits in " + human_bytes(static_cast<double>(run.max_memory_bytes)) +
                        "; the estimated peak is " + e.describe() + ". What would lower it:" + e.how_to_lower());
}

uint64_t location_seed(uint64_t seed, const std::string& location) {
  return mix64(seed ^ hash_string(location.data(), location.size()));
}

// What the stages of one run share as it goes from location to location: its inputs, the
// output, the shard numbering, the share's item count and one progress line per stage over
// the whole run (tiles: per location, as a location's tiles are known only once its LiDAR
// is accumulated and planned). Stages interleave per location; each line is finished when
// its stage's last location is done.
struct RunState {
  RunState(const GenerateConfig& config_, const GenerateRun& run_, const nuscenes::Database& db_,
           const CameraSetup& camera_setup_, const StageTotals& totals_, GenerateSummary& summary_)
      : config(config_),
        run(run_),
        db(db_),
        camera_setup(camera_setup_),
        totals(totals_),
        summary(summary_),
        out(run_.out, config_, run_.share),
        per_shard(config_.output.resolved_tiles_per_shard()),
        lidar_progress("lidar sweeps", totals_.all_sweeps, run_.progress) {
    if (camera_setup.cameras) camera_progress.emplace("camera images", totals.all_images, run.progress);
    for (const auto& [l, n] : totals.scenes) scenes_total += n;
  }
  const GenerateConfig& config;
  const GenerateRun& run;
  const nuscenes::Database& db;
  const CameraSetup& camera_setup;
  const StageTotals& totals;
  GenerateSummary& summary;
  std::vector<std::pair<nuscenes::Index, const ExcludedScene*>> excluded;  // scenes.exclude, scene order
  OutputWriter out;
  const int64_t per_shard;
  std::map<std::string, int64_t> next_shard;  // per split
  size_t item_index = 0;                      // the run's work items so far (share assignment)
  std::vector<PlanFilters> filters;           // per location, for an empty plan's explanation
  Progress lidar_progress;
  std::optional<Progress> camera_progress;
  size_t scenes_done = 0, scenes_total = 0, images_decoded = 0;
};

// One location's pass through the stages.
struct LocationRun {
  std::string location;
  bool last = false;                    // the run's last location: its stage lines finish
  std::vector<nuscenes::Index> scenes;  // the location's scenes less the excluded ones
  LocationState st;
};

void log_excluded_scenes(const nuscenes::Database& db,
                         const std::vector<std::pair<nuscenes::Index, const ExcludedScene*>>& excluded) {
  if (excluded.empty()) return;
  std::vector<std::string> named;
  for (const auto& [s, e] : excluded)
    named.push_back(db.scene[s].name + (e->reason.empty() ? "" : " (" + e->reason + ")"));
  log::info(strprintf("generate: leaving out %zu scene(s) (scenes.exclude): ", excluded.size()) + join(named, ", "));
}

// Stage 1 of splits.preset map-update: the prior map's lane graph and index, every lane
// token's change label between it and the current map, and the manifest's map_update record.
void prior_map_stage(RunState& rs, LocationRun& lr, const nuscenes::MapExpansion& map) {
  LocationState& st = lr.st;
  const std::filesystem::path file = prior_map_file(rs.config, lr.location);
  NSG_CHECK(std::filesystem::is_regular_file(file), ConfigError, file.string(), "splits.prior_maps",
            "the prior map expansion of " + lr.location +
                " (a synthetic release made with config changes has it; for two real map versions give their "
                "folder with --set splits.prior_maps=DIR)");
  const nuscenes::MapExpansion prior = nuscenes::load_map_expansion_file(file);
  Issues prior_defects;  // counted in the record, as the current map's are (never fatal)
  st.prior_graph = graph::build_lane_graph(prior, rs.config.graph, &prior_defects);
  st.prior_index = std::make_unique<graph::SegmentIndex>(st.prior_graph);
  st.changes = graph::lane_changes_between(prior, map);
  std::map<graph::MapChange, int64_t> lanes;
  for (const auto& [token, change] : st.changes) ++lanes[change];
  nlohmann::ordered_json by_label = nlohmann::ordered_json::object();  // every label, in the enum's order
  for (const graph::MapChange c : {graph::MapChange::kUnchanged, graph::MapChange::kAdded, graph::MapChange::kRemoved,
                                   graph::MapChange::kMoved, graph::MapChange::kRetyped})
    by_label[graph::map_change_name(c)] = lanes[c];
  st.plan.map_update = {
      {"date", rs.config.split_date},
      {"prior_map",
       {{"file", rs.config.prior_maps.empty() ? "maps/prior/expansion/" + lr.location + ".json" : file.string()},
        {"sha256", sha256_file(file)},
        {"bytes", static_cast<int64_t>(std::filesystem::file_size(file))},
        {"map_defects", static_cast<int64_t>(prior_defects.items().size())}}},
      {"scenes", 0},
      {"lanes", by_label}};
}

// Stage 1: the location's lane graph and its segment index.
void build_graph_stage(RunState& rs, LocationRun& lr) {
  const auto t0 = std::chrono::steady_clock::now();
  LocationState& st = lr.st;
  Issues defects;
  {  // the map's records are not needed past the graph (a city's map holds ~150 MB)
    const nuscenes::MapExpansion map = nuscenes::load_map_expansion(rs.config.dataroot, lr.location);
    st.graph = graph::build_lane_graph(map, rs.config.graph, &defects);
    st.plan.map_version = map.version();
    if (rs.config.split_preset == SplitPreset::kMapUpdate) prior_map_stage(rs, lr, map);
  }
  st.index = std::make_unique<graph::SegmentIndex>(st.graph);
  st.plan.graph_nodes = st.graph.nodes.size();
  st.plan.graph_edges = st.graph.edges.size();
  st.plan.graph_lanes = st.graph.lanes.size();
  st.plan.map_defects = defects.items().size();
  rs.summary.seconds.graph_s += seconds_since(t0);
  log_memory(lr.location + ": lane graph built");
}

// Stage 2: the LiDAR (and vehicle) layers of the location's scenes.
void lidar_stage(RunState& rs, LocationRun& lr) {
  LocationState& st = lr.st;
  lr.scenes = location_scenes(rs.db, rs.config, lr.location);
  for (const auto& [index, e] : rs.excluded)
    if (rs.db.log[rs.db.scene[index].log].location == lr.location)
      st.plan.excluded_scenes.push_back({rs.db.scene[index].name, e->reason});
  st.plan.scenes_used = lr.scenes.size();
  const auto t0 = std::chrono::steady_clock::now();
  if (lr.scenes.empty())
    log::warn("generate: " + lr.location + ": every scene is excluded (scenes.exclude): no LiDAR, no tiles");
  else log::info(strprintf("generate: %s: accumulating LiDAR of %zu scene(s)", lr.location.c_str(), lr.scenes.size()));
  st.sources = layer_sources(rs.db, rs.config, lr.scenes);
  for (LayerSource& src : st.sources) {
    if (st.sources.size() > 1)
      log::info(strprintf("generate: %s: %zu scene(s) %s for %s", lr.location.c_str(), src.scenes.size(),
                          src.name.c_str(), join(src.splits, ", ").c_str()));
    src.layers = accumulate_layers(rs.db, rs.config, src.scenes, rs.run.threads, &rs.lidar_progress);
    rs.summary.sweeps += src.layers.stats.sweeps;
    const raster::LocationLayers& l = src.layers;
    log_memory(lr.location + ": LiDAR accumulated: " +
               strprintf("%zu blocks, %zu covered cells, %zu B a block besides its cells (LiDAR layer %s, vehicle "
                         "layer %s over %zu blocks)",
                         l.stats.lidar_blocks, l.stats.covered_cells, packed_block_overhead_bytes(l.lidar),
                         human_bytes(static_cast<double>(l.lidar.cells().memory_bytes())).c_str(),
                         human_bytes(static_cast<double>(l.vehicles.cells().memory_bytes())).c_str(),
                         l.vehicles.cells().block_count()));
    rs.scenes_done += l.stats.scenes;
  }
  rs.summary.seconds.lidar_s += seconds_since(t0);
  rs.lidar_progress.set_detail(strprintf("%zu/%zu scenes", rs.scenes_done, rs.scenes_total));
  if (lr.last) rs.lidar_progress.finish();
}

// splits.preset before-after: how near the test tiles come to the train tiles (they share
// streets by design), logged and recorded in the plan.
void log_time_split(RunState& rs, LocationRun& lr) {
  const TimeSplitLeakage leak = time_split_leakage(lr.st.plan.crops, rs.config.resolution_m, rs.config.crops.size_px);
  lr.st.plan.time_split = time_split_json(rs.config, lr.st.sources, leak);
  log::info(
      strprintf("generate: %s: before-after split at %s (a temporal split over the same streets): %lld of %lld "
                "test tiles overlap a train tile; median distance to the nearest train tile %s",
                lr.location.c_str(), rs.config.split_date.c_str(), static_cast<long long>(leak.overlapping_train),
                static_cast<long long>(leak.test_tiles),
                leak.median_distance_m ? strprintf("%.1f m", *leak.median_distance_m).c_str() : "(none)"));
}

// Stage 3: split regions, crops, tile keys and shards (the same in every share).
void plan_stage(RunState& rs, LocationRun& lr) {
  LocationState& st = lr.st;
  const auto t0 = std::chrono::steady_clock::now();
  const uint64_t seed = location_seed(rs.config.seed, lr.location);
  PlanFilters& filter = rs.filters.emplace_back();
  filter.location = lr.location;
  filter.scenes_used = st.plan.scenes_used;
  filter.scenes_excluded = st.plan.excluded_scenes.size();
  if (rs.config.split_preset != SplitPreset::kBeforeAfter) {  // regions, map-update: by place
    const raster::LidarLayer& lidar = st.sources.front().layers.lidar;
    st.plan.regions = tiling::plan_regions(lidar, rs.config.split_options_for(lr.location), rs.config.crop_size_m(),
                                           seed, &filter.regions);
    st.plan.crops = tiling::plan_crops(lidar, st.plan.regions, rs.config.crops, seed, &filter.crops);
  } else {
    plan_time_split(st.sources, rs.config, seed, st.plan.regions, st.plan.crops, &filter.crops);
    filter.time_split = time_split_sides(rs.db, st.sources);
  }
  if (!st.plan.map_update.is_null())
    st.plan.map_update["scenes"] = static_cast<int64_t>(st.sources.front().scenes.size());
  assign_keys_and_shards(st.plan, rs.per_shard, rs.next_shard);
  if (rs.config.split_preset == SplitPreset::kBeforeAfter) log_time_split(rs, lr);
  st.plan.rung_shards = plan_rung_shards(st.plan, rs.config.ladder);
  rs.summary.tiles_planned += st.plan.crops.size();
  rs.summary.seconds.plan_s += seconds_since(t0);
  log::info(strprintf("generate: %s: %zu regions, %zu train / %zu val / %zu test tiles", lr.location.c_str(),
                      st.plan.regions.size(), st.plan.count("train"), st.plan.count("val"), st.plan.count("test")));
}

// The location's work items (its maps, its shards) this share does and has not done yet.
std::vector<WorkItem> share_items(RunState& rs, const LocationRun& lr) {
  std::vector<WorkItem> items;
  items.push_back({ItemKind::kMaps, 0, 0, "maps/" + lr.location});
  for (size_t s = 0; s < lr.st.plan.shards.size(); ++s)
    items.push_back({ItemKind::kShard, 0, s, rs.out.shard_item_id(lr.st.plan.shards[s])});
  for (size_t s = 0; s < lr.st.plan.rung_shards.size(); ++s)
    items.push_back({ItemKind::kRungShard, 0, s, rs.out.shard_item_id(lr.st.plan.rung_shards[s].shard)});
  std::vector<WorkItem> mine;
  for (const WorkItem& item : items) {
    const bool ours =
        rs.item_index++ % static_cast<size_t>(rs.run.share.count) == static_cast<size_t>(rs.run.share.index);
    if (!ours) continue;
    if (rs.out.verified(item.id)) {
      ++rs.summary.items_skipped;
      continue;
    }
    mine.push_back(item);
  }
  return mine;
}

// The location's images count as done for this share whether it decodes them or not.
void camera_stage_done(RunState& rs, const LocationRun& lr) {
  if (!rs.camera_progress) return;
  rs.camera_progress->set_detail(strprintf("%zu decoded", rs.images_decoded));
  rs.camera_progress->advance(rs.totals.images.at(lr.location));
  if (lr.last) rs.camera_progress->finish();
}

// One rectangle of cells per tile of the shards in `mine` that `source` makes.
std::vector<raster::CellRect> tile_rects(const RunState& rs, const LocationRun& lr, const std::vector<WorkItem>& mine,
                                         const LayerSource& source) {
  std::vector<raster::CellRect> rects;
  for (const WorkItem& item : mine) {
    if (item.kind != ItemKind::kShard || !source.serves(lr.st.plan.shards[item.shard].split)) continue;
    const PlannedShard& s = lr.st.plan.shards[item.shard];
    for (size_t i = s.first; i < s.first + s.count; ++i) {
      const tiling::Crop& c = lr.st.plan.crops[i];
      rects.push_back({c.col0, c.row0, c.col0 + rs.config.crops.size_px, c.row0 + rs.config.crops.size_px});
    }
  }
  return rects;
}

// Stage 4: camera colours and semantics, only for the cells of this share's tiles, each
// source's from its own scenes. Returns the number of tiles coloured.
size_t camera_stage(RunState& rs, LocationRun& lr, const std::vector<WorkItem>& mine) {
  const auto t0 = std::chrono::steady_clock::now();
  size_t tiles = 0;
  for (LayerSource& src : lr.st.sources) {
    const std::vector<raster::CellRect> rects = tile_rects(rs, lr, mine, src);
    tiles += rects.size();
    if (rs.camera_setup.cameras && !rects.empty() && !src.scenes.empty()) {
      if (rs.totals.images.at(lr.location) > 0)
        log::info(strprintf("generate: %s: colouring %zu tiles from the cameras", lr.location.c_str(), rects.size()));
      else if (rs.camera_setup.lidarseg)  // a LiDAR-only release with lidarseg: semantics only
        log::info(strprintf("generate: %s: semantics of %zu tiles from lidarseg (no camera images)",
                            lr.location.c_str(), rects.size()));
    }
    src.color = camera_layers(rs.db, rs.config, rs.camera_setup, src.scenes, src.layers.lidar, rects, rs.run.threads,
                              lr.location);
    rs.summary.images += src.color.stats().images_used;
    rs.images_decoded += src.color.stats().images_used;
    // The point index and the lidarseg layer were freed as many small blocks, which glibc
    // keeps in the heap: give them back before the tile stage adds its own (city world with
    // lidarseg, 1 thread: peak RSS 841 -> 729 MB).
    malloc_trim(0);
    log_memory(lr.location + ": cameras done" +
               strprintf(" (%zu points indexed, colour layer %s over %zu blocks)", src.color.stats().points,
                         human_bytes(static_cast<double>(src.color.cells().memory_bytes())).c_str(),
                         src.color.cells().block_count()));
  }
  camera_stage_done(rs, lr);
  rs.summary.seconds.camera_s += seconds_since(t0);
  return tiles;
}

// The layers the tiles of `split` are cut from.
tiling::LocationRasters rasters_for(const RunState& rs, const LocationState& st, const std::string& split) {
  const LayerSource& src = source_for(st.sources, split);
  tiling::LocationRasters out{&src.layers.lidar, rs.camera_setup.cameras ? &src.color : nullptr, &src.layers.vehicles,
                              &st.graph, st.index.get()};
  if (st.prior_index) {
    out.prior_graph = &st.prior_graph;
    out.prior_index = st.prior_index.get();
    out.changes = &st.changes;
  }
  return out;
}

// A rung shard of the ladder: its tiles rebuilt from their first k scenes, written like a
// split shard under its own name (and, in the folder layout, tiles/<split>-r<k>/).
size_t write_rung_shard(RunState& rs, const LocationRun& lr, const WorkItem& item, Progress* progress) {
  const RungShard& r = lr.st.plan.rung_shards[item.shard];
  const tiling::LocationRasters layers = rasters_for(rs, lr.st, r.shard.split);
  const RungInputs inputs{rs.db, rs.config, rs.camera_setup, lr.st.plan, layers, rs.run.threads};
  std::vector<std::vector<TileFile>> encoded = encode_rung_shard(inputs, r, &rs.summary.ladder);
  return rs.out.write_tiles(
      item.id, r.shard, lr.location, r.shard.split + "-r" + rung_name(r.rung),
      [&](size_t i) { return std::move(encoded[i - r.shard.first]); }, rs.run, progress);
}

// Tiles in the share's items: the progress total of the tiles stage.
size_t item_tiles(const LocationPlan& plan, const std::vector<WorkItem>& mine) {
  size_t n = 0;
  for (const WorkItem& item : mine) {
    if (item.kind == ItemKind::kShard) n += plan.shards[item.shard].count;
    if (item.kind == ItemKind::kRungShard) n += plan.rung_shards[item.shard].shard.count;
  }
  return n;
}

// Stage 5: this share's maps and shards of the location.
void tiles_stage(RunState& rs, const LocationRun& lr, const std::vector<WorkItem>& mine, size_t tiles) {
  const auto t0 = std::chrono::steady_clock::now();
  const LocationState& st = lr.st;
  std::optional<Progress> tile_progress;
  if (tiles > 0) tile_progress.emplace("tiles " + lr.location, tiles, rs.run.progress);
  for (const WorkItem& item : mine) {
    if (item.kind == ItemKind::kMaps) {
      rs.out.write_maps(item.id, lr.location, st.graph, st.plan);
    } else if (item.kind == ItemKind::kRungShard) {
      rs.summary.tiles_written += write_rung_shard(rs, lr, item, tile_progress ? &*tile_progress : nullptr);
    } else {
      Progress* progress = tile_progress ? &*tile_progress : nullptr;
      const PlannedShard& shard = st.plan.shards[item.shard];
      rs.summary.tiles_written +=
          rs.out.write_shard(item.id, rs.db, st.plan, shard, rasters_for(rs, st, shard.split), rs.run, progress);
    }
    ++rs.summary.items_done;
  }
  if (tile_progress) tile_progress->finish();
  rs.summary.seconds.tiles_s += seconds_since(t0);
  log_memory(lr.location + ": tiles written");
}

// One location through every stage; what this share does of it is written.
void generate_location(RunState& rs, size_t location_index) {
  LocationRun lr;
  lr.location = rs.summary.locations[location_index];
  lr.last = location_index + 1 == rs.summary.locations.size();
  lr.st.plan.location = lr.location;
  build_graph_stage(rs, lr);
  lidar_stage(rs, lr);
  plan_stage(rs, lr);
  const std::vector<WorkItem> mine = share_items(rs, lr);
  rs.out.add_plan(plan_json(lr.st.plan));
  if (mine.empty()) return camera_stage_done(rs, lr);
  camera_stage(rs, lr, mine);
  tiles_stage(rs, lr, mine, item_tiles(lr.st.plan, mine));
}

// The whole plan is known here, the same in every share: an empty dataset is refused by
// all shares alike (the done-records stay incomplete, so no merge writes a manifest).
void check_plan_not_empty(const RunState& rs) {
  if (rs.summary.tiles_planned == 0) {
    const std::string why = explain_empty_plan(rs.filters, rs.config);
    if (!rs.run.allow_empty) throw EmptyDatasetError("", "", why);
    log::warn(why + "\n(--allow-empty: writing the empty dataset)");
  } else {
    for (const std::string& w : empty_split_warnings(rs.filters, rs.config)) log::warn("generate: " + w);
  }
}

}  // namespace

GenerateSummary generate(const GenerateConfig& given, const GenerateRun& run) {
  // The values were checked where they were read (the config's declarations); a run needs
  // its inputs too.
  given.check_inputs();
  // camera.semantic_source auto becomes the source this release has, before anything reads
  // the config: the manifest records it, and a resumed run resolves the same way.
  GenerateConfig config = given;
  raster::resolve_semantic_source(config.raster.camera, config.dataroot, config.version);
  run.share.validate();
  if (!run.check_inputs_only) prepare_output_folder(run.out, config, run.share, run.overwrite);
  log::info("generate: " + data_licence_line());
  GenerateSummary summary;
  auto t0 = std::chrono::steady_clock::now();
  const nuscenes::Database db = nuscenes::Database::load(config.dataroot, config.version);
  summary.seconds.load_s = seconds_since(t0);
  summary.locations = resolve_locations(config, db);
  const CameraSetup camera_setup = prepare_cameras(db, config);
  std::vector<char> excluded;
  auto excluded_list = find_excluded_scenes(config, db, summary.locations, excluded);
  for (const auto& [s, e] : excluded_list) summary.excluded_scenes.push_back(db.scene[s].name);
  log_excluded_scenes(db, excluded_list);
  // Every file the stages will open, before the first of them (a missing mask was found
  // only after the LiDAR stage), and the memory the run will need.
  log::info("generate: inputs present: " + check_run_inputs(db, config, summary.locations, excluded).describe());
  check_memory(db, summary.locations, excluded, config, run);
  if (run.check_inputs_only) {
    log::info("generate: --check-inputs: the inputs are complete; nothing written");
    return summary;
  }

  const StageTotals totals = count_stage_work(db, summary.locations, config.raster.lidar_channel, excluded);
  RunState rs(config, run, db, camera_setup, totals, summary);
  rs.excluded = std::move(excluded_list);
  for (size_t i = 0; i < summary.locations.size(); ++i) generate_location(rs, i);
  check_plan_not_empty(rs);
  log_ladder_work(summary);
  rs.out.finish();
  if (run.share.count == 1) {
    t0 = std::chrono::steady_clock::now();
    merge(run.out);
    summary.manifest_written = true;
    summary.seconds.merge_s = seconds_since(t0);
  }
  return summary;
}

}  // namespace nsg::pipeline
