#include "nsg/pipeline/config.h"

#include <cmath>
#include <fstream>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/strings.h"

namespace nsg::pipeline {

using nlohmann::json;
using nlohmann::ordered_json;

int64_t OutputOptions::resolved_tiles_per_shard() const {
  if (tiles_per_shard > 0) return tiles_per_shard;
  return std::max<int64_t>(1, static_cast<int64_t>(shard_target_mb * 1024.0 / estimated_tile_kb));
}

void OutputOptions::validate() const {
  if (tiles_per_shard < 0) throw ConfigError("", "output.tiles_per_shard", "a count ≥ 0 (0 = from the target size)");
  if (!(shard_target_mb > 0 && shard_target_mb <= 1e6))
    throw ConfigError("", "output.shard_target_mb", "a size in (0, 1e6] MB");
  if (!(estimated_tile_kb > 0 && estimated_tile_kb <= 1e6))
    throw ConfigError("", "output.estimated_tile_kb", "a size in (0, 1e6] KB");
  if (deflate_level < 1 || deflate_level > 9) throw ConfigError("", "output.deflate_level", "a zlib level 1 to 9");
}

std::vector<ExcludedScene> default_excluded_scenes() {
  const std::string bad_fit = "boston-seaport: the ego poses fit the map badly (nuScenes devkit README, map_api blacklist)";
  const std::string off_map = "boston-seaport: lies outside the annotated map (nuScenes devkit README, map_api blacklist)";
  return {{"scene-0499", bad_fit},
          {"scene-0501", off_map},
          {"scene-0502", off_map},
          {"scene-0515", bad_fit},
          {"scene-0517", bad_fit}};
}

tiling::SplitOptions GenerateConfig::split_options_for(const std::string& location) const {
  tiling::SplitOptions s = splits;
  auto it = regions.find(location);
  s.regions = it == regions.end() ? std::vector<tiling::Region>{} : it->second;
  return s;
}

void GenerateConfig::validate(bool require_inputs) const {
  if (require_inputs && dataroot.empty()) throw ConfigError("", "dataroot", "the nuScenes dataroot (--dataroot)");
  if (require_inputs && version.empty()) throw ConfigError("", "version", "a release version such as v1.0-mini (--version)");
  std::set<std::string> excluded;
  for (const ExcludedScene& e : exclude_scenes) {
    if (e.name.empty()) throw ConfigError("", "scenes.exclude", "scene names that are not empty");
    if (!excluded.insert(e.name).second)
      throw ConfigError("", "scenes.exclude", "each scene once ('" + e.name + "' repeats)");
  }
  if (!(resolution_m > 0.0 && resolution_m <= 10.0)) throw ConfigError("", "resolution_m", "metres per pixel in (0, 10]");
  if (std::abs(raster.lidar.resolution_m - resolution_m) > 1e-12)
    throw InternalError("", "raster.lidar.resolution_m", "equal to resolution_m");
  raster.validate();
  graph.validate();
  crops.validate();
  for (const auto& [location, list] : regions) split_options_for(location).validate(crop_size_m());
  splits.validate(crop_size_m());
  output.validate();
}

namespace {

std::string layout_name(Layout l) { return l == Layout::kTar ? "tar" : "folder"; }

ordered_json region_json(const tiling::Region& r) {
  const tiling::RectM& b = r.bounds;
  return {{"name", r.name}, {"split", r.split}, {"bounds_m", {b.x_west_m, b.y_south_m, b.x_east_m, b.y_north_m}}};
}

// Every key of `doc` must exist in `shape` (the defaults); objects recurse. "regions" is
// keyed by location, so only its values are checked (by the reader).
void check_keys(const json& doc, const ordered_json& shape, const std::string& path, const std::string& file) {
  if (!doc.is_object()) return;
  for (const auto& [key, value] : doc.items()) {
    const std::string here = path.empty() ? key : path + "." + key;
    if (!shape.contains(key)) throw ConfigError(file, here, "a known config key (see samples/generate.json)");
    if (key == "regions" && path == "splits") continue;
    if (value.is_object() && shape[key].is_object()) check_keys(value, shape[key], here, file);
  }
}

// Typed access to the merged document with errors naming file and key path.
class Reader {
 public:
  Reader(const json& doc, std::string file) : doc_(doc), file_(std::move(file)) {}

  const json& at(const std::string& path) const {
    const json* node = &doc_;
    for (const std::string& part : split(path, '.')) {
      if (!node->is_object() || !node->contains(part)) throw ConfigError(file_, path, "a value");
      node = &(*node)[part];
    }
    return *node;
  }
  double num(const std::string& path) const {
    const json& v = at(path);
    if (!v.is_number()) throw ConfigError(file_, path, "a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw ConfigError(file_, path, "a finite number");
    return d;
  }
  int64_t integer(const std::string& path) const {
    const json& v = at(path);
    if (!v.is_number_integer() && !(v.is_number() && std::floor(v.get<double>()) == v.get<double>()))
      throw ConfigError(file_, path, "an integer");
    return v.get<int64_t>();
  }
  uint64_t seed(const std::string& path) const {
    const json& v = at(path);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0))
      throw ConfigError(file_, path, "a non-negative integer seed");
    return v.get<uint64_t>();
  }
  bool boolean(const std::string& path) const {
    const json& v = at(path);
    if (!v.is_boolean()) throw ConfigError(file_, path, "true or false");
    return v.get<bool>();
  }
  std::string str(const std::string& path) const {
    const json& v = at(path);
    if (!v.is_string()) throw ConfigError(file_, path, "a string");
    return v.get<std::string>();
  }
  std::vector<std::string> strings(const std::string& path) const {
    const json& v = at(path);
    if (!v.is_array()) throw ConfigError(file_, path, "an array of strings");
    std::vector<std::string> out;
    for (const json& s : v) {
      if (!s.is_string()) throw ConfigError(file_, path, "an array of strings");
      out.push_back(s.get<std::string>());
    }
    return out;
  }
  const std::string& file() const { return file_; }

 private:
  const json& doc_;
  std::string file_;
};

std::vector<tiling::Region> read_regions(const json& list, const std::string& path, const std::string& file) {
  if (!list.is_array()) throw ConfigError(file, path, "an array of {name, split, bounds_m}");
  std::vector<tiling::Region> out;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string here = path + "[" + std::to_string(i) + "]";
    const json& r = list[i];
    if (!r.is_object() || !r.contains("name") || !r.contains("split") || !r.contains("bounds_m") || r.size() != 3 ||
        !r["name"].is_string() || !r["split"].is_string() || !r["bounds_m"].is_array() || r["bounds_m"].size() != 4)
      throw ConfigError(file, here, "{\"name\": text, \"split\": train|val|test, \"bounds_m\": [x_west, y_south, x_east, y_north]}");
    double b[4];
    for (int k = 0; k < 4; ++k) {
      if (!r["bounds_m"][k].is_number()) throw ConfigError(file, here + ".bounds_m", "four numbers (metres)");
      b[k] = r["bounds_m"][k].get<double>();
    }
    out.push_back({r["name"].get<std::string>(), r["split"].get<std::string>(), {b[0], b[1], b[2], b[3]}});
  }
  return out;
}

std::vector<ExcludedScene> read_excluded_scenes(const json& list, const std::string& path, const std::string& file) {
  const char* shape = "an array of {\"name\": scene name, \"reason\": text} ([] keeps every scene)";
  if (!list.is_array()) throw ConfigError(file, path, shape);
  std::vector<ExcludedScene> out;
  for (size_t i = 0; i < list.size(); ++i) {
    const json& e = list[i];
    if (!e.is_object() || e.size() != 2 || !e.contains("name") || !e.contains("reason") || !e["name"].is_string() ||
        !e["reason"].is_string())
      throw ConfigError(file, path + "[" + std::to_string(i) + "]", shape);
    out.push_back({e["name"].get<std::string>(), e["reason"].get<std::string>()});
  }
  return out;
}

}  // namespace

ordered_json config_to_json(const GenerateConfig& c) {
  ordered_json regions = ordered_json::object();
  for (const auto& [location, list] : c.regions) {
    ordered_json arr = ordered_json::array();
    for (const tiling::Region& r : list) arr.push_back(region_json(r));
    regions[location] = arr;
  }
  const raster::CameraOptions& cam = c.raster.camera;
  ordered_json excluded = ordered_json::array();
  for (const ExcludedScene& e : c.exclude_scenes) excluded.push_back({{"name", e.name}, {"reason", e.reason}});
  return ordered_json{
      {"schema_version", "1"},
      {"dataroot", c.dataroot},
      {"version", c.version},
      {"locations", c.locations},
      {"scenes", {{"exclude", excluded}}},
      {"seed", c.seed},
      {"resolution_m", c.resolution_m},
      {"lidar",
       {{"channel", c.raster.lidar_channel},
        {"roof_half_size_m", c.raster.lidar.roof_half_size_m},
        {"max_range_m", c.raster.lidar.max_range_m}}},
      {"camera",
       {{"rgb", cam.rgb},
        {"semantic", cam.semantic},
        {"semantic_root", cam.semantic_root.string()},
        {"semantic_source", cam.semantic_source == raster::SemanticSource::kLidarseg ? "lidarseg" : "masks"},
        {"lidarseg_labels", cam.lidarseg_labels.string()},
        {"view_radius_m", cam.view_radius_m},
        {"min_depth_m", cam.min_depth_m},
        {"occlusion_window_px", cam.occlusion_window_px},
        {"occlusion_side_px", cam.occlusion_side_px},
        {"occlusion_height_m", cam.occlusion_height_m},
        {"occlusion_margin_m", cam.occlusion_margin_m},
        {"jpeg_scale_denom", cam.jpeg_scale_denom}}},
      {"vehicles",
       {{"detections", c.raster.detections_file.string()},
        {"score_threshold", c.raster.detection_score_threshold}}},
      {"graph",
       {{"max_spacing_m", c.graph.max_spacing_m},
        {"source_resolution_m", c.graph.source_resolution_m},
        {"join_tolerance_m", c.graph.join_tolerance_m},
        {"strict", c.graph.strict}}},
      {"splits",
       {{"ratios", {{"train", c.splits.ratios.train}, {"val", c.splits.ratios.val}, {"test", c.splits.ratios.test}}},
        {"buffer_m", c.splits.buffer_m},
        {"block_size_m", c.splits.block_size_m},
        {"min_block_coverage", c.splits.min_block_coverage},
        {"regions", regions}}},
      {"crops",
       {{"size_px", c.crops.size_px},
        {"min_lidar_coverage", c.crops.min_lidar_coverage},
        {"placement",
         {{"train", tiling::placement_name(c.crops.train)},
          {"val", tiling::placement_name(c.crops.val)},
          {"test", tiling::placement_name(c.crops.test)}}},
        {"random_per_km2", c.crops.random_per_km2},
        {"random_total", c.crops.random_total},
        {"attempts_per_crop", c.crops.attempts_per_crop}}},
      {"output",
       {{"layout", layout_name(c.output.layout)},
        {"tiles_per_shard", c.output.tiles_per_shard},
        {"shard_target_mb", c.output.shard_target_mb},
        {"estimated_tile_kb", c.output.estimated_tile_kb},
        {"deflate_level", c.output.deflate_level}}}};
}

GenerateConfig config_from_json(const json& doc, const std::string& file, GenerateConfig base) {
  if (!doc.is_object()) throw ConfigError(file, "", "a JSON object (the generate config)");
  const ordered_json shape = config_to_json(base);
  check_keys(doc, shape, "", file);
  if (doc.contains("schema_version") && doc["schema_version"] != "1")
    throw ConfigError(file, "schema_version", "\"1\"");
  // The document over the defaults; explicit regions replace (not merge with) the defaults.
  json merged = json::parse(shape.dump());
  merged.merge_patch(doc);
  if (doc.contains("splits") && doc["splits"].is_object() && doc["splits"].contains("regions"))
    merged["splits"]["regions"] = doc["splits"]["regions"];
  const Reader r(merged, file);

  GenerateConfig c;
  c.dataroot = r.str("dataroot");
  c.version = r.str("version");
  c.locations = r.strings("locations");
  c.exclude_scenes = read_excluded_scenes(r.at("scenes.exclude"), "scenes.exclude", file);
  c.seed = r.seed("seed");
  c.resolution_m = r.num("resolution_m");
  c.raster.lidar.resolution_m = c.resolution_m;
  c.raster.lidar_channel = r.str("lidar.channel");
  c.raster.lidar.roof_half_size_m = r.num("lidar.roof_half_size_m");
  c.raster.lidar.max_range_m = r.num("lidar.max_range_m");
  raster::CameraOptions& cam = c.raster.camera;
  cam.rgb = r.boolean("camera.rgb");
  cam.semantic = r.boolean("camera.semantic");
  cam.semantic_root = r.str("camera.semantic_root");
  const std::string source = r.str("camera.semantic_source");
  if (source != "masks" && source != "lidarseg")
    throw ConfigError(file, "camera.semantic_source", "\"masks\" (class-id masks of the camera images) or \"lidarseg\" "
                                                      "(nuScenes-lidarseg point labels), got \"" + source + "\"");
  cam.semantic_source = source == "lidarseg" ? raster::SemanticSource::kLidarseg : raster::SemanticSource::kMasks;
  cam.lidarseg_labels = r.str("camera.lidarseg_labels");
  cam.view_radius_m = r.num("camera.view_radius_m");
  cam.min_depth_m = r.num("camera.min_depth_m");
  cam.occlusion_window_px = static_cast<int>(r.integer("camera.occlusion_window_px"));
  cam.occlusion_side_px = static_cast<int>(r.integer("camera.occlusion_side_px"));
  cam.occlusion_height_m = r.num("camera.occlusion_height_m");
  cam.occlusion_margin_m = r.num("camera.occlusion_margin_m");
  cam.jpeg_scale_denom = static_cast<int>(r.integer("camera.jpeg_scale_denom"));
  cam.lidar_channel = c.raster.lidar_channel;
  c.raster.detections_file = r.str("vehicles.detections");
  c.raster.detection_score_threshold = r.num("vehicles.score_threshold");
  c.graph.max_spacing_m = r.num("graph.max_spacing_m");
  c.graph.source_resolution_m = r.num("graph.source_resolution_m");
  c.graph.join_tolerance_m = r.num("graph.join_tolerance_m");
  c.graph.strict = r.boolean("graph.strict");
  c.splits.ratios = {r.num("splits.ratios.train"), r.num("splits.ratios.val"), r.num("splits.ratios.test")};
  c.splits.buffer_m = r.num("splits.buffer_m");
  c.splits.block_size_m = r.num("splits.block_size_m");
  c.splits.min_block_coverage = r.num("splits.min_block_coverage");
  const json& regions = r.at("splits.regions");
  if (!regions.is_object()) throw ConfigError(file, "splits.regions", "an object: location → list of regions");
  for (const auto& [location, list] : regions.items())
    c.regions[location] = read_regions(list, "splits.regions." + location, file);
  c.crops.size_px = static_cast<int>(r.integer("crops.size_px"));
  c.crops.min_lidar_coverage = r.num("crops.min_lidar_coverage");
  c.crops.train = tiling::parse_placement(r.str("crops.placement.train"), "crops.placement.train");
  c.crops.val = tiling::parse_placement(r.str("crops.placement.val"), "crops.placement.val");
  c.crops.test = tiling::parse_placement(r.str("crops.placement.test"), "crops.placement.test");
  c.crops.random_per_km2 = r.num("crops.random_per_km2");
  c.crops.random_total = r.integer("crops.random_total");
  c.crops.attempts_per_crop = static_cast<int>(r.integer("crops.attempts_per_crop"));
  const std::string layout = r.str("output.layout");
  if (layout != "tar" && layout != "folder") throw ConfigError(file, "output.layout", "'tar' or 'folder'");
  c.output.layout = layout == "tar" ? Layout::kTar : Layout::kFolder;
  c.output.tiles_per_shard = r.integer("output.tiles_per_shard");
  c.output.shard_target_mb = r.num("output.shard_target_mb");
  c.output.estimated_tile_kb = r.num("output.estimated_tile_kb");
  c.output.deflate_level = static_cast<int>(r.integer("output.deflate_level"));
  try {
    c.validate(/*require_inputs=*/false);
  } catch (const ConfigError& e) {
    // Values come from this file: name it.
    throw ConfigError(file, e.record(), e.expected());
  }
  return c;
}

GenerateConfig load_generate_config(const std::filesystem::path& file) {
  const std::string text = read_file(file);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw ParseError(file.string(), "byte " + std::to_string(e.byte), "valid JSON (" + std::string(e.what()) + ")");
  }
  return config_from_json(doc, file.string());
}

void apply_setting(GenerateConfig& config, const std::string& assignment) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("", "--set " + assignment, "key.path=value (e.g. crops.min_lidar_coverage=0.4)");
  const std::string path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  json value;
  try {
    value = json::parse(text);  // numbers, booleans, arrays, objects
  } catch (const json::parse_error&) {
    value = text;  // anything else is a string
  }
  json patch = value;
  const std::vector<std::string> parts = split(path, '.');
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) patch = json{{*it, patch}};
  config = config_from_json(patch, "--set " + path, config);
}

}  // namespace nsg::pipeline
