#include "nsg/pipeline/generate.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
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
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/rng.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/geometry/georef.h"
#include "nsg/graph/from_map.h"
#include "nsg/graph/geojson.h"
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

size_t LocationPlan::count(const std::string& split) const {
  return static_cast<size_t>(
      std::count_if(crops.begin(), crops.end(), [&](const tiling::Crop& c) { return c.split == split; }));
}

ordered_json plan_json(const LocationPlan& p) {
  ordered_json regions = ordered_json::array();
  for (const tiling::Region& r : p.regions)
    regions.push_back(io::region_to_json(
        {r.name, r.split, {r.bounds.x_west_m, r.bounds.y_south_m, r.bounds.x_east_m, r.bounds.y_north_m}}));
  ordered_json counts = ordered_json::object();
  for (std::string_view s : tiling::kSplitNames) counts[std::string(s)] = p.count(std::string(s));
  ordered_json shards = ordered_json::array();
  for (const PlannedShard& s : p.shards)
    shards.push_back({{"name", s.name},
                      {"split", s.split},
                      {"tiles", s.count},
                      {"first_key", p.keys[s.first]},
                      {"last_key", p.keys[s.first + s.count - 1]}});
  ordered_json excluded = ordered_json::array();
  for (const ExcludedScene& e : p.excluded_scenes) excluded.push_back({{"name", e.name}, {"reason", e.reason}});
  return {
      {"name", p.location},
      {"map_version", p.map_version},
      {"lane_graph",
       {{"nodes", p.graph_nodes}, {"edges", p.graph_edges}, {"lanes", p.graph_lanes}, {"map_defects", p.map_defects}}},
      {"scenes", {{"used", p.scenes_used}, {"excluded", excluded}}},
      {"regions", regions},
      {"counts", counts},
      {"shards", shards}};
}

namespace {

// Everything a location needs while its items run.
struct LocationState {
  LocationPlan plan;
  graph::LaneGraph graph;
  std::unique_ptr<graph::SegmentIndex> index;
  raster::LocationLayers layers;
};

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

// Orders crops by split (train, val, test), names them and cuts shards of `per_shard`.
void assign_keys_and_shards(LocationPlan& plan, int64_t per_shard, std::map<std::string, int64_t>& next_shard) {
  std::vector<tiling::Crop> ordered;
  for (std::string_view split : tiling::kSplitNames) {
    const size_t first = ordered.size();
    for (const tiling::Crop& c : plan.crops)
      if (c.split == split) ordered.push_back(c);
    for (size_t i = first; i < ordered.size(); ++i)
      plan.keys.push_back(tiling::tile_key(plan.location, std::string(split), static_cast<int64_t>(i - first)));
    for (size_t i = first; i < ordered.size(); i += static_cast<size_t>(per_shard)) {
      PlannedShard s;
      s.split = std::string(split);
      s.name = s.split + "-" + strprintf("%06lld", static_cast<long long>(next_shard[s.split]++));
      s.first = i;
      s.count = std::min(static_cast<size_t>(per_shard), ordered.size() - i);
      plan.shards.push_back(s);
    }
  }
  plan.crops = std::move(ordered);
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
  const auto excluded_list = find_excluded_scenes(config, db, summary.locations, excluded);
  if (!excluded_list.empty()) {
    std::vector<std::string> named;
    for (const auto& [s, e] : excluded_list) {
      summary.excluded_scenes.push_back(db.scene[s].name);
      named.push_back(db.scene[s].name + (e->reason.empty() ? "" : " (" + e->reason + ")"));
    }
    log::info(strprintf("generate: leaving out %zu scene(s) (scenes.exclude): ", excluded_list.size()) +
              join(named, ", "));
  }
  std::vector<PlanFilters> filters;
  // Every file the stages will open, before the first of them (a missing mask was found
  // only after the LiDAR stage).
  log::info("generate: inputs present: " + check_run_inputs(db, config, summary.locations, excluded).describe());
  check_memory(db, summary.locations, excluded, config, run);
  if (run.check_inputs_only) {
    log::info("generate: --check-inputs: the inputs are complete; nothing written");
    return summary;
  }

  OutputWriter out(run.out, config, run.share);
  const int64_t per_shard = config.output.resolved_tiles_per_shard();
  std::map<std::string, int64_t> next_shard;
  size_t item_index = 0;
  // One progress line per stage over the whole run (tiles: per location, as a location's
  // tiles are known only once its LiDAR is accumulated and planned). Stages interleave
  // per location; each line is finished when its stage's last location is done.
  const StageTotals totals = count_stage_work(db, summary.locations, config.raster.lidar_channel, excluded);
  const bool cameras = camera_setup.cameras;
  Progress lidar_progress("lidar sweeps", totals.all_sweeps, run.progress);
  std::optional<Progress> camera_progress;
  if (cameras) camera_progress.emplace("camera images", totals.all_images, run.progress);
  size_t scenes_done = 0, scenes_total = 0, images_decoded = 0;
  for (const auto& [l, n] : totals.scenes) scenes_total += n;
  for (size_t location_index = 0; location_index < summary.locations.size(); ++location_index) {
    const std::string& location = summary.locations[location_index];
    const bool last_location = location_index + 1 == summary.locations.size();
    LocationState st;
    st.plan.location = location;
    t0 = std::chrono::steady_clock::now();
    Issues defects;
    {  // the map's records are not needed past the graph (a city's map holds ~150 MB)
      const nuscenes::MapExpansion map = nuscenes::load_map_expansion(config.dataroot, location);
      st.graph = graph::build_lane_graph(map, config.graph, &defects);
      st.plan.map_version = map.version();
    }
    st.index = std::make_unique<graph::SegmentIndex>(st.graph);
    st.plan.graph_nodes = st.graph.nodes.size();
    st.plan.graph_edges = st.graph.edges.size();
    st.plan.graph_lanes = st.graph.lanes.size();
    st.plan.map_defects = defects.items().size();
    summary.seconds.graph_s += seconds_since(t0);
    log_memory(location + ": lane graph built");

    // The location's scenes less the excluded ones.
    const std::vector<nuscenes::Index> scenes = location_scenes(db, config, location);
    for (const auto& [index, e] : excluded_list)
      if (db.log[db.scene[index].log].location == location)
        st.plan.excluded_scenes.push_back({db.scene[index].name, e->reason});
    st.plan.scenes_used = scenes.size();

    t0 = std::chrono::steady_clock::now();
    if (scenes.empty())
      log::warn("generate: " + location + ": every scene is excluded (scenes.exclude): no LiDAR, no tiles");
    else log::info(strprintf("generate: %s: accumulating LiDAR of %zu scene(s)", location.c_str(), scenes.size()));
    st.layers = accumulate_layers(db, config, scenes, run.threads, &lidar_progress);
    summary.sweeps += st.layers.stats.sweeps;
    summary.seconds.lidar_s += seconds_since(t0);
    log_memory(location + ": LiDAR accumulated: " +
               strprintf("%zu blocks, %zu covered cells, %zu B a block besides its cells (LiDAR layer %s, vehicle "
                         "layer %s over %zu blocks)",
                         st.layers.stats.lidar_blocks, st.layers.stats.covered_cells,
                         packed_block_overhead_bytes(st.layers.lidar),
                         human_bytes(static_cast<double>(st.layers.lidar.cells().memory_bytes())).c_str(),
                         human_bytes(static_cast<double>(st.layers.vehicles.cells().memory_bytes())).c_str(),
                         st.layers.vehicles.cells().block_count()));
    scenes_done += st.layers.stats.scenes;
    lidar_progress.set_detail(strprintf("%zu/%zu scenes", scenes_done, scenes_total));
    if (last_location) lidar_progress.finish();

    t0 = std::chrono::steady_clock::now();
    const uint64_t seed = location_seed(config.seed, location);
    PlanFilters& filter = filters.emplace_back();
    filter.location = location;
    filter.scenes_used = st.plan.scenes_used;
    filter.scenes_excluded = st.plan.excluded_scenes.size();
    st.plan.regions = tiling::plan_regions(st.layers.lidar, config.split_options_for(location), config.crop_size_m(),
                                           seed, &filter.regions);
    st.plan.crops = tiling::plan_crops(st.layers.lidar, st.plan.regions, config.crops, seed, &filter.crops);
    assign_keys_and_shards(st.plan, per_shard, next_shard);
    summary.tiles_planned += st.plan.crops.size();
    summary.seconds.plan_s += seconds_since(t0);
    log::info(strprintf("generate: %s: %zu regions, %zu train / %zu val / %zu test tiles", location.c_str(),
                        st.plan.regions.size(), st.plan.count("train"), st.plan.count("val"), st.plan.count("test")));

    // This location's items, and the ones this share does.
    std::vector<WorkItem> items;
    items.push_back({ItemKind::kMaps, 0, 0, "maps/" + location});
    for (size_t s = 0; s < st.plan.shards.size(); ++s)
      items.push_back({ItemKind::kShard, 0, s, out.shard_item_id(st.plan.shards[s])});
    std::vector<WorkItem> mine;
    for (const WorkItem& item : items) {
      const bool ours = item_index++ % static_cast<size_t>(run.share.count) == static_cast<size_t>(run.share.index);
      if (!ours) continue;
      if (out.verified(item.id)) {
        ++summary.items_skipped;
        continue;
      }
      mine.push_back(item);
    }
    out.add_plan(plan_json(st.plan));
    // The location's images count as done for this share whether it decodes them or not.
    const auto camera_stage_done = [&] {
      if (!camera_progress) return;
      camera_progress->set_detail(strprintf("%zu decoded", images_decoded));
      camera_progress->advance(totals.images.at(location));
      if (last_location) camera_progress->finish();
    };
    if (mine.empty()) {
      camera_stage_done();
      continue;
    }

    // Camera colours only for the cells of this share's tiles.
    t0 = std::chrono::steady_clock::now();
    std::vector<raster::CellRect> rects;
    for (const WorkItem& item : mine) {
      if (item.kind != ItemKind::kShard) continue;
      const PlannedShard& s = st.plan.shards[item.shard];
      for (size_t i = s.first; i < s.first + s.count; ++i) {
        const tiling::Crop& c = st.plan.crops[i];
        rects.push_back({c.col0, c.row0, c.col0 + config.crops.size_px, c.row0 + config.crops.size_px});
      }
    }
    if (cameras && !rects.empty() && !scenes.empty())
      log::info(strprintf("generate: %s: colouring %zu tiles from the cameras", location.c_str(), rects.size()));
    const raster::ColorLayer color =
        camera_layers(db, config, camera_setup, scenes, st.layers.lidar, rects, run.threads, location);
    summary.images += color.stats().images_used;
    images_decoded += color.stats().images_used;
    camera_stage_done();
    summary.seconds.camera_s += seconds_since(t0);
    log_memory(location + ": cameras done" +
               strprintf(" (%zu points indexed, colour layer %s over %zu blocks)", color.stats().points,
                         human_bytes(static_cast<double>(color.cells().memory_bytes())).c_str(),
                         color.cells().block_count()));

    t0 = std::chrono::steady_clock::now();
    const tiling::LocationRasters layers{&st.layers.lidar, cameras ? &color : nullptr, &st.layers.vehicles, &st.graph,
                                         st.index.get()};
    // rects holds one rectangle per tile of this share at the location.
    std::optional<Progress> tile_progress;
    if (!rects.empty()) tile_progress.emplace("tiles " + location, rects.size(), run.progress);
    for (const WorkItem& item : mine) {
      if (item.kind == ItemKind::kMaps) {
        out.write_maps(item.id, location, st.graph, st.plan);
      } else {
        Progress* progress = tile_progress ? &*tile_progress : nullptr;
        summary.tiles_written +=
            out.write_shard(item.id, db, st.plan, st.plan.shards[item.shard], layers, run, progress);
      }
      ++summary.items_done;
    }
    if (tile_progress) tile_progress->finish();
    summary.seconds.tiles_s += seconds_since(t0);
    log_memory(location + ": tiles written");
  }
  // The whole plan is known here, the same in every share: an empty dataset is refused by
  // all shares alike (the done-records stay incomplete, so no merge writes a manifest).
  if (summary.tiles_planned == 0) {
    const std::string why = explain_empty_plan(filters, config);
    if (!run.allow_empty) throw EmptyDatasetError("", "", why);
    log::warn(why + "\n(--allow-empty: writing the empty dataset)");
  } else {
    for (const std::string& w : empty_split_warnings(filters, config)) log::warn("generate: " + w);
  }
  out.finish();
  if (run.share.count == 1) {
    t0 = std::chrono::steady_clock::now();
    merge(run.out);
    summary.manifest_written = true;
    summary.seconds.merge_s = seconds_since(t0);
  }
  return summary;
}

}  // namespace nsg::pipeline
