// `nsgraph frames`: the key frames of a release on a generated dataset's regions.
#include "nsg/frames/export.h"

#include <algorithm>
#include <optional>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <set>

#include "internal.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/version.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/log.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/progress.h"
#include "nsg/core/rng.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/frames/leakage.h"
#include "nsg/graph/from_map.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/frames_documents.h"
#include "nsg/nuscenes/map_expansion.h"
#include "nsg/frames/frame_map.h"
#include "nsg/pipeline/config.h"

namespace nsg::frames {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

// What the export takes from the dataset: its config (release, graph options, buffer,
// ratios, excluded scenes) and, per location, its regions and map file digest.
struct DatasetPlan {
  fs::path manifest_path;
  fs::path release;  // the release it was generated from (io::release_folder)
  std::string manifest_sha256;
  pipeline::GenerateConfig config;
  std::vector<std::string> locations;  // manifest order
  std::map<std::string, std::vector<tiling::Region>> regions;
  std::map<std::string, std::string> map_sha256;
  std::map<std::string, std::string> map_version;
};

tiling::Region region_of(const io::Region& r) {
  tiling::Region out;
  out.name = r.name;
  out.split = r.split;
  out.bounds = {r.bounds_m[0], r.bounds_m[1], r.bounds_m[2], r.bounds_m[3]};
  return out;
}

// The manifest through its one reader (io/manifest.h: every field checked); the config
// through its own (pipeline::config_from_json).
DatasetPlan read_dataset(const fs::path& root) {
  const io::Dataset dataset = io::Dataset::open(root);
  const io::Manifest& m = dataset.manifest();
  DatasetPlan p;
  p.manifest_path = root / "manifest.json";
  p.manifest_sha256 = sha256_file(p.manifest_path);
  p.config = pipeline::config_from_json(json(m.config), p.manifest_path.string() + ":/config");
  p.release = io::release_folder(m.inputs, root);
  for (const io::ManifestLocation& loc : m.locations) {
    p.locations.push_back(loc.name);
    for (const io::Region& r : loc.regions) p.regions[loc.name].push_back(region_of(r));
    const io::MapExpansionRecord* map = m.inputs.map_of(loc.name);
    NSG_CHECK(map != nullptr, ParseError, p.manifest_path.string(), "/inputs/map_expansion/" + loc.name,
              "the map expansion file of location " + loc.name);
    p.map_sha256[loc.name] = map->file.sha256;
    p.map_version[loc.name] = map->version;
  }
  return p;
}

// A location's lane graph, built as the dataset's was (same map file, same graph options).
// Both on the heap: the index refers to the graph, which must not move.
struct LocationGraph {
  std::unique_ptr<graph::LaneGraph> graph;
  std::unique_ptr<graph::SegmentIndex> index;
  LocationMapElements elements;  // lanelines, crossings, road boundaries (frame_map.h)
};

LocationGraph location_graph(const fs::path& dataroot, const std::string& location, const DatasetPlan& plan) {
  const fs::path file =
      dataroot / "maps" / "expansion" /
      (safe_name(location, plan.manifest_path.string(), "location '" + printable_text(location) + "'") + ".json");
  NSG_CHECK(fs::exists(file), IoError, file.string(), location,
            "the map expansion the dataset " + plan.manifest_path.string() + " was generated from");
  NSG_CHECK(sha256_file(file) == plan.map_sha256.at(location), DataError, file.string(), location,
            "the map expansion the dataset was generated from (sha256 " + plan.map_sha256.at(location) + " in " +
                plan.manifest_path.string() + "): the frames' lanes would not be the tiles'");
  const nuscenes::MapExpansion map = nuscenes::load_map_expansion(dataroot, location);
  LocationGraph out;
  Issues issues;
  out.graph = std::make_unique<graph::LaneGraph>(graph::build_lane_graph(map, plan.config.graph, &issues));
  out.index = std::make_unique<graph::SegmentIndex>(*out.graph);
  out.elements = location_map_elements(map, *out.graph);
  return out;
}

const tiling::Region* region_containing(const std::vector<tiling::Region>& regions, double x, double y) {
  for (const tiling::Region& r : regions)
    if (x >= r.bounds.x_west_m && x <= r.bounds.x_east_m && y >= r.bounds.y_south_m && y <= r.bounds.y_north_m)
      return &r;
  return nullptr;
}

bool window_near_other_split(const std::vector<Eigen::Vector2d>& window, const std::vector<tiling::Region>& regions,
                             const std::string& split, double buffer_m) {
  for (const tiling::Region& r : regions)
    if (r.split != split && polygon_rect_distance(window, r.bounds) < buffer_m) return true;
  return false;
}

// The scenes-random draw: each scene's split from a seeded hash of its token and the
// dataset's split ratios (the way nuScenes' official split assigns whole scenes).
std::string random_scene_split(const std::string& scene_token, uint64_t seed, const tiling::SplitRatios& ratios) {
  const uint64_t h = mix64(seed ^ hash_string(scene_token.data(), scene_token.size()));
  const double u = static_cast<double>(h >> 11) * 0x1.0p-53;
  if (u < ratios.train) return "train";
  if (u < ratios.train + ratios.val) return "val";
  return "test";
}

// What an export of ours consists of in its folder: --overwrite removes files there only,
// and only those the earlier manifest lists.
const std::vector<std::string> kExportEntries = {"manifest.json", "data_dict.json", "train", "val", "test"};

// The export's own files in `out`: removed by --overwrite (only those its manifest lists),
// refused without it; `out` is never the dataset or the release it reads.
void prepare_out(const OutputFolder& out, bool overwrite, const fs::path& dataset, const fs::path& dataroot) {
  refuse_out_over_input(out.root(), dataset, "--dataset");
  refuse_out_over_input(out.root(), dataroot, "the release (--dataroot or the dataset's config)");
  const fs::path manifest = out.path("manifest.json");
  std::set<std::string> listed;
  if (fs::exists(fs::symlink_status(manifest))) {
    NSG_CHECK(overwrite, ConfigError, out.root().string(), "--out",
              "a folder without a frames export: " + manifest.string() +
                  " is one (or another manifest); add --overwrite to replace that export, or choose another --out");
    // --overwrite replaces a frames export only (read by its one reader): a dataset's (or
    // anything else's) manifest there means --out points at the wrong folder.
    metrics::FramesManifest old;
    try {
      old = metrics::read_frames_manifest(out.root());
    } catch (const Error& e) {
      throw ConfigError(manifest.string(), "--out",
                        std::string("a frames export to replace: this manifest.json is not one (") + e.what() +
                            "); is --out the dataset's folder?");
    }
    listed.insert("manifest.json");
    for (const metrics::FramesListedFile& f : old.files) listed.insert(f.path);
  }
  const int64_t removed = out.remove_listed(listed, kExportEntries, "the earlier export's manifest.json");
  if (removed > 0)
    log::info("frames: --overwrite: removed the " + std::to_string(removed) + " file(s) of the export in " +
              out.root().string());
  fs::create_directories(out.root());
}

struct WrittenFile {
  std::string path;  // relative to the export
  uint64_t bytes = 0;
  std::string sha256;
};

void place_image(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::remove(to, ec);  // OutputFolder::prepare refused a link there: this is a file of ours
  fs::create_hard_link(from, to, ec);
  if (ec) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

ordered_json by_distance_json(const std::vector<LeakageBand>& bands) {
  ordered_json out = ordered_json::array();
  for (const LeakageBand& b : bands)
    out.push_back({{"from_m", b.from_m},
                   {"to_m", b.to_m},
                   {"window_cells", b.window_cells},
                   {"seen_cells", b.seen_cells},
                   {"share_seen", b.window_cells > 0 ? ordered_json(static_cast<double>(b.seen_cells) / b.window_cells)
                                                     : ordered_json(nullptr)}});
  return out;
}

ordered_json leakage_json(const Leakage& l, double radius_m) {
  const auto maybe = [](const std::optional<double>& v) { return v ? ordered_json(*v) : ordered_json(nullptr); };
  return {{"test_frames", l.test_frames},
          {"train_frames", l.train_frames},
          {"radius_m", radius_m},
          {"test_within_radius", l.test_within_radius},
          {"share_within_radius", maybe(l.share_within)},
          {"median_distance_m", maybe(l.median_distance_m)},
          {"by_distance", by_distance_json(l.by_distance)}};
}

}  // namespace

int64_t FramesSummary::total_frames() const {
  int64_t n = 0;
  for (const auto& [location, counts] : frames) n += counts[0] + counts[1] + counts[2];
  return n;
}

nlohmann::ordered_json summary_json(const FramesSummary& s, const FramesConfig& config) {
  ordered_json by_location = ordered_json::object();
  std::array<int64_t, 3> totals{};
  for (const auto& [location, counts] : s.frames) {
    ordered_json c = ordered_json::object();
    for (size_t i = 0; i < 3; ++i) {
      c[std::string(tiling::kSplitNames[i])] = counts[i];
      totals[i] += counts[i];
    }
    by_location[location] = c;
  }
  ordered_json per_split = ordered_json::object();
  for (size_t i = 0; i < 3; ++i) per_split[std::string(tiling::kSplitNames[i])] = totals[i];
  return {{"key_frames", s.key_frames},
          {"frames", per_split},
          {"frames_by_location", by_location},
          {"dropped",
           {{"other_location", s.dropped.other_location},
            {"excluded_scene", s.dropped.excluded_scene},
            {"outside_regions", s.dropped.outside_regions},
            {"overlap", s.dropped.overlap},
            {"no_ego_pose", s.dropped.no_ego_pose}}},
          {"flagged_overlap", s.flagged_overlap},
          {"centerlines", s.centerlines},
          {"links", s.links},
          {"lanelines_from_offset", s.lanelines_from_offset},
          {"areas", {{"pedestrian_crossing", s.pedestrian_crossings}, {"road_boundary", s.road_boundaries}}},
          {"leakage",
           {{"regions", leakage_json(s.regions, config.leak_radius_m)},
            {"scenes_random", leakage_json(s.scenes_random, config.leak_radius_m)}}}};
}

namespace {

// A key frame to export, ordered by (location in manifest order, scene name, timestamp):
// records and the data_dict come out in one order whatever the release's table order.
struct Candidate {
  size_t location;
  std::string scene;
  int64_t timestamp;
  nuscenes::Index sample;
};

// The release's key frames of the dataset's locations and kept scenes, in export order;
// the others are counted in `summary`.
std::vector<Candidate> collect_candidates(const nuscenes::Database& db, const DatasetPlan& plan,
                                          FramesSummary& summary) {
  std::set<std::string> excluded;
  for (const pipeline::ExcludedScene& e : plan.config.exclude_scenes) excluded.insert(e.name);
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < db.sample.size(); ++i) {
    const nuscenes::Sample& s = db.sample.rows()[i];
    ++summary.key_frames;
    const nuscenes::Scene& scene = db.scene[s.scene];
    const std::string& location = db.log[scene.log].location;
    const auto at = std::find(plan.locations.begin(), plan.locations.end(), location);
    if (at == plan.locations.end()) {
      ++summary.dropped.other_location;
      continue;
    }
    if (excluded.count(scene.name)) {
      ++summary.dropped.excluded_scene;
      continue;
    }
    candidates.push_back({static_cast<size_t>(at - plan.locations.begin()), scene.name, s.timestamp_us,
                          static_cast<nuscenes::Index>(i)});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.location, a.scene, a.timestamp, a.sample) < std::tie(b.location, b.scene, b.timestamp, b.sample);
  });
  return candidates;
}

// What the frames of one export share: the inputs, and what the frames add up to.
struct ExportState {
  const FramesConfig& config;
  const FramesRun& run;
  const OutputFolder& out;
  std::string scene_table, sensor_table;  // named by errors about a scene's or channel's name
  const DatasetPlan& plan;
  const nuscenes::Database& db;
  const std::map<std::string, LocationGraph>& graphs;
  FramesSummary& summary;
  std::vector<EgoPosition> by_regions, by_scenes;  // ego positions and their split, per preset
  std::vector<WrittenFile> files;
  ordered_json data_dict = ordered_json::object();
};

// The frame's split (by the preset), region and overlap, or nullopt when it is dropped
// (counted in the summary); records its ego position for both presets' leakage figures.
std::optional<FrameContext> frame_context(ExportState& es, const Candidate& c) {
  const std::string& location = es.plan.locations[c.location];
  const nuscenes::Index lidar = es.db.key_frame(c.sample, "LIDAR_TOP");
  if (lidar == nuscenes::kNoIndex) {
    ++es.summary.dropped.no_ego_pose;
    return std::nullopt;
  }
  const nuscenes::EgoPose& pose = es.db.ego_pose[es.db.sample_data[lidar].ego_pose];
  FrameContext context;
  context.sample = c.sample;
  context.location = location;
  context.map_version = es.plan.map_version.at(location);
  context.global_from_ego = rigid(pose.translation, pose.rotation);
  const double x = pose.translation[0], y = pose.translation[1];
  const std::vector<tiling::Region>& regions = es.plan.regions.at(location);
  const tiling::Region* region = region_containing(regions, x, y);
  if (region == nullptr) {
    ++es.summary.dropped.outside_regions;
    return std::nullopt;
  }
  context.overlap = window_near_other_split(window_corners_global(context.global_from_ego, es.config.window), regions,
                                            region->split, es.plan.config.splits.buffer_m);
  if (context.overlap && es.config.overlap == OverlapMode::kDrop) {
    ++es.summary.dropped.overlap;
    return std::nullopt;
  }
  if (context.overlap && es.config.overlap == OverlapMode::kFlag) ++es.summary.flagged_overlap;
  context.flag_overlap = es.config.overlap == OverlapMode::kFlag;
  const nuscenes::Scene& scene = es.db.scene[es.db.sample[c.sample].scene];
  const std::string drawn = random_scene_split(scene.token.str(), es.config.seed, es.plan.config.splits.ratios);
  const Eigen::Matrix3d& r = context.global_from_ego.rotation;
  const double yaw_rad = std::atan2(r(1, 0), r(0, 0));  // the ego x axis in the map
  es.by_regions.push_back({location, x, y, tiling::split_index(region->split), yaw_rad});
  es.by_scenes.push_back({location, x, y, tiling::split_index(drawn), yaw_rad});
  if (es.config.split_preset == SplitPreset::kRegions) {
    context.split = region->split;
    context.region = region->name;
  } else {
    context.split = drawn;
  }
  ++es.summary.frames[location][static_cast<size_t>(tiling::split_index(context.split))];
  return context;
}

void count_map_elements(const FrameMapElements& elements, FramesSummary& summary) {
  for (const FrameLaneSegment& s : elements.lane_segments)
    summary.lanelines_from_offset += int64_t{s.left_from_offset} + int64_t{s.right_from_offset};
  for (const FrameArea& a : elements.areas)
    ++(a.category == AreaCategory::kPedestrianCrossing ? summary.pedestrian_crossings : summary.road_boundaries);
}

// Writes the frame's record (and its camera images with copy_images).
void write_frame(ExportState& es, const Candidate& c, FrameContext& context, const FrameLanes& lanes,
                 const FrameMapElements& elements) {
  const nuscenes::Scene& scene = es.db.scene[es.db.sample[c.sample].scene];
  // The scene name becomes the record's folder (OpenLane-V2's segment_id): checked first.
  const std::string& scene_name = safe_name(
      scene.name, es.scene_table, "scene '" + printable_text(scene.name) + "' (token " + scene.token.str() + ")");
  const std::string folder = context.split + "/" + scene_name;
  if (es.config.copy_images) context.image_root = folder + "/image";
  const std::string name = std::to_string(c.timestamp) + ".json";
  const std::string text = frame_record_text(es.db, context, lanes, elements);
  const std::string relative = folder + "/info/" + name;
  // Durable at the flush before data_dict.json and the manifest (write_export_manifest).
  es.out.write(relative, text, Durability::kDeferred);
  es.files.push_back({relative, text.size(), sha256_hex(text)});
  es.data_dict[context.split][scene_name].push_back(name);
  if (!es.config.copy_images) return;
  for (const nuscenes::Index sd : camera_key_frames(es.db, c.sample)) {
    const nuscenes::SampleData& data = es.db.sample_data[sd];
    const std::string& channel =
        safe_name(es.db.channel(data), es.sensor_table, "channel of sample_data " + data.token.str());
    const std::string image = context.image_root + "/" + channel + "/" + std::to_string(c.timestamp) + ".jpg";
    const fs::path target = es.out.prepare(image);
    place_image(es.db.file_path(data), target);
    es.files.push_back({image, fs::file_size(target), sha256_file(target)});
  }
}

// data_dict.json and manifest.json, which lists every file written with its sha256.
void write_export_manifest(ExportState& es, const fs::path& dataroot) {
  flush_file_system(es.out.root());  // every record on disk before the documents that list them
  const std::string dict_text = es.data_dict.dump(1) + "\n";
  es.out.write("data_dict.json", dict_text);
  es.files.push_back({"data_dict.json", dict_text.size(), sha256_hex(dict_text)});
  std::sort(es.files.begin(), es.files.end(),
            [](const WrittenFile& a, const WrittenFile& b) { return a.path < b.path; });
  ordered_json listed = ordered_json::array();
  for (const WrittenFile& f : es.files) {
    listed.push_back({{"path", f.path}, {"bytes", f.bytes}, {"sha256", f.sha256}});
    es.summary.bytes += static_cast<int64_t>(f.bytes);
  }
  es.summary.files = static_cast<int64_t>(es.files.size());
  const FramesConfig& config = es.config;
  const ordered_json manifest = {
      {"schema_version", "1"},
      {"kind", "nsgraph-frames"},
      {"tool_version", kVersion},
      {"source",
       {{"dataset", path_relative_to(es.run.dataset, es.run.out)},
        {"dataset_manifest_sha256", es.plan.manifest_sha256},
        {"dataroot", path_relative_to(dataroot, es.run.out)},
        {"version", es.plan.config.version},
        {"split_buffer_m", es.plan.config.splits.buffer_m}}},
      {"config", frames_option_table().to_json(config)},
      {"layout",
       {{"records", "<split>/<segment_id>/info/<timestamp>.json (OpenLane-V2's info layout; segment_id = scene name)"},
        {"images", config.copy_images ? "<split>/<segment_id>/image/<camera>/<timestamp>.jpg, relative to this folder"
                                      : "referenced: image_path is relative to source.dataroot"},
        {"traffic_elements",
         "none: nuScenes has no traffic-element annotations, so traffic_element is [] and topology_lcte n x 0"}}},
      {"counts", summary_json(es.summary, config)},
      {"files", listed}};
  es.out.write("manifest.json", manifest.dump(1) + "\n");
}

}  // namespace

FramesSummary export_frames(const FramesConfig& config, const FramesRun& run) {
  config.validate();
  NSG_CHECK(!run.dataset.empty(), ConfigError, "", "--dataset", "a generated dataset folder (manifest.json)");
  NSG_CHECK(run.stats_only || !run.out.empty(), ConfigError, "", "--out", "an output folder");
  const DatasetPlan plan = read_dataset(run.dataset);
  const fs::path dataroot = config.dataroot.empty() ? plan.release : fs::path(config.dataroot);
  NSG_CHECK(!config.dataroot.empty() || fs::is_directory(dataroot), ConfigError, plan.manifest_path.string(),
            "/inputs/dataroot",
            "the release the dataset was generated from at " + dataroot.string() +
                " (the path is kept relative to the dataset's folder); it is not there: pass --dataroot <release>");
  const nuscenes::Database db = nuscenes::Database::load(dataroot, plan.config.version);
  std::map<std::string, LocationGraph> graphs;
  for (const std::string& location : plan.locations) graphs.emplace(location, location_graph(dataroot, location, plan));
  const OutputFolder out(run.stats_only ? fs::path(".") : run.out);
  if (!run.stats_only) prepare_out(out, run.overwrite, run.dataset, dataroot);

  FramesSummary summary;
  const std::vector<Candidate> candidates = collect_candidates(db, plan, summary);
  const auto start = std::chrono::steady_clock::now();
  const fs::path tables = dataroot / plan.config.version;
  ExportState es{config,
                 run,
                 out,
                 (tables / "scene.json").string(),
                 (tables / "sensor.json").string(),
                 plan,
                 db,
                 graphs,
                 summary,
                 {},
                 {},
                 {},
                 ordered_json::object()};
  Progress progress("frames", candidates.size(), run.progress);
  for (const Candidate& c : candidates) {
    progress.advance();
    std::optional<FrameContext> context = frame_context(es, c);
    if (!context) continue;
    const LocationGraph& g = graphs.at(context->location);
    const FrameLanes lanes =
        cut_frame_lanes(*g.graph, *g.index, context->global_from_ego, config.window, config.centerline_points);
    const FrameMapElements elements =
        cut_frame_map(lanes, g.elements, context->global_from_ego, config.window, config.lane_segment_points);
    summary.centerlines += static_cast<int64_t>(lanes.centerlines.size());
    summary.links += static_cast<int64_t>(lanes.successors.size());
    count_map_elements(elements, summary);
    if (!run.stats_only) write_frame(es, c, *context, lanes, elements);
  }
  progress.finish();
  summary.regions = measure_leakage(es.by_regions, config.leak_radius_m, config.window);
  summary.scenes_random = measure_leakage(es.by_scenes, config.leak_radius_m, config.window);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (run.stats_only) return summary;
  write_export_manifest(es, dataroot);
  log::info(
      strprintf("frames: %lld frames (%lld key frames in the release), %lld centerlines, %lld links; %.3f s for the "
                "records",
                static_cast<long long>(summary.total_frames()), static_cast<long long>(summary.key_frames),
                static_cast<long long>(summary.centerlines), static_cast<long long>(summary.links), summary.seconds));
  return summary;
}

}  // namespace nsg::frames
