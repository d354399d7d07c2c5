#include "nsg/pipeline/config.h"

#include <cmath>
#include <regex>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/strings.h"
#include "nsg/raster/raster_options.h"

namespace nsg::pipeline {

using nlohmann::json;
using nlohmann::ordered_json;
using options::Spec;

int64_t OutputOptions::resolved_tiles_per_shard() const {
  if (tiles_per_shard > 0) return tiles_per_shard;
  return std::max<int64_t>(1, static_cast<int64_t>(shard_target_mb * 1024.0 / estimated_tile_kb));
}

std::vector<ExcludedScene> default_excluded_scenes() {
  const std::string bad_fit =
      "boston-seaport: the ego poses fit the map badly (nuScenes devkit README, map_api blacklist)";
  const std::string off_map =
      "boston-seaport: lies outside the annotated map (nuScenes devkit README, map_api blacklist)";
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

void GenerateConfig::check_inputs() const {
  if (dataroot.empty()) throw ConfigError("", "dataroot", "the nuScenes dataroot (--dataroot)");
  if (version.empty()) throw ConfigError("", "version", "a release version such as v1.0-mini (--version)");
}

void GenerateConfig::check_split_preset() const {
  const bool date_ok = std::regex_match(split_date, std::regex(R"(\d{4}-\d{2}-\d{2})"));
  if (split_preset != SplitPreset::kMapUpdate && !prior_maps.empty())
    throw ConfigError("", "splits.prior_maps", "\"\" unless splits.preset is map-update");
  if (split_preset == SplitPreset::kRegions) {
    if (!split_date.empty())
      throw ConfigError("", "splits.before_after_date", "\"\" unless splits.preset is before-after or map-update");
    return;
  }
  if (split_preset == SplitPreset::kMapUpdate) {
    if (!date_ok)
      throw ConfigError("", "splits.before_after_date",
                        "a date YYYY-MM-DD for splits.preset map-update (the date of the release's changes.json)");
    return;
  }
  if (!date_ok) throw ConfigError("", "splits.before_after_date", "a date YYYY-MM-DD for splits.preset before-after");
  if (!regions.empty())
    throw ConfigError("", "splits.regions", "{} with splits.preset before-after (the dates make the splits)");
}

void GenerateConfig::check_relations(const options::Origins& origins) const {
  try {
    if (std::abs(raster.lidar.resolution_m - resolution_m) > 1e-12)
      throw InternalError("", "raster.lidar.resolution_m", "equal to resolution_m");
    for (const auto& [location, list] : regions) split_options_for(location).check_relations(crop_size_m());
    splits.check_relations(crop_size_m());
    check_split_preset();
  } catch (const ConfigError& e) {
    options::rethrow_from_origin(e, origins);  // the value came from the source that set the key last
  }
}

void GenerateConfig::validate(bool require_inputs) const {
  if (require_inputs) check_inputs();
  generate_option_table().check(*this);
  check_relations();
}

namespace {

const char* kRegionShape =
    "{\"name\": text, \"split\": train|val|test, \"bounds_m\": [x_west, y_south, x_east, y_north]}";

std::vector<tiling::Region> read_regions(const json& list, const std::string& path) {
  if (!list.is_array()) throw ConfigError("", path, std::string("an array of ") + kRegionShape);
  std::vector<tiling::Region> out;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string here = path + "[" + std::to_string(i) + "]";
    const json& r = list[i];
    if (!r.is_object() || !r.contains("name") || !r.contains("split") || !r.contains("bounds_m") || r.size() != 3 ||
        !r["name"].is_string() || !r["split"].is_string() || !r["bounds_m"].is_array() || r["bounds_m"].size() != 4)
      throw ConfigError("", here, kRegionShape);
    double b[4];
    for (int k = 0; k < 4; ++k) {
      if (!r["bounds_m"][k].is_number()) throw ConfigError("", here + ".bounds_m", "four numbers (metres)");
      b[k] = r["bounds_m"][k].get<double>();
    }
    out.push_back({r["name"].get<std::string>(), r["split"].get<std::string>(), {b[0], b[1], b[2], b[3]}});
  }
  return out;
}

ordered_json regions_json(const std::map<std::string, std::vector<tiling::Region>>& regions) {
  ordered_json out = ordered_json::object();
  for (const auto& [location, list] : regions) {
    ordered_json arr = ordered_json::array();
    for (const tiling::Region& r : list) {
      const tiling::RectM& b = r.bounds;
      arr.push_back(
          {{"name", r.name}, {"split", r.split}, {"bounds_m", {b.x_west_m, b.y_south_m, b.x_east_m, b.y_north_m}}});
    }
    out[location] = arr;
  }
  return out;
}

std::vector<ExcludedScene> read_excluded_scenes(const json& list, const Spec& spec) {
  std::vector<ExcludedScene> out;
  if (!list.is_array()) options::reject(list, spec);
  std::set<std::string> names;
  for (size_t i = 0; i < list.size(); ++i) {
    const json& e = list[i];
    const std::string here = spec.key + "[" + std::to_string(i) + "]";
    if (!e.is_object() || e.size() != 2 || !e.contains("name") || !e.contains("reason") || !e["name"].is_string() ||
        !e["reason"].is_string() || e["name"].get_ref<const std::string&>().empty())
      throw ConfigError("", here, spec.expected());
    if (!names.insert(e["name"].get<std::string>()).second)
      throw ConfigError("", here, "each scene once ('" + e["name"].get<std::string>() + "' repeats)");
    out.push_back({e["name"].get<std::string>(), e["reason"].get<std::string>()});
  }
  return out;
}

const options::Table<OutputOptions>& output_option_table() {
  static const options::Table<OutputOptions> table = [] {
    options::Table<OutputOptions> t;
    t.choice("output.layout", &OutputOptions::layout, {{"tar", Layout::kTar}, {"folder", Layout::kFolder}})
        .help("WebDataset tar shards, or the same files in folders");
    t.integer("output.tiles_per_shard", &OutputOptions::tiles_per_shard)
        .range(options::at_least(0))
        .help("Tiles per shard (0 = shard_target_mb / estimated_tile_kb)");
    t.number("output.shard_target_mb", &OutputOptions::shard_target_mb)
        .unit("MB")
        .range(options::above_up_to(0, 1e6))
        .help("Shard size aimed at when tiles_per_shard is 0");
    t.number("output.estimated_tile_kb", &OutputOptions::estimated_tile_kb)
        .unit("KB")
        .range(options::above_up_to(0, 1e6))
        .help("Tile size assumed when tiles_per_shard is 0");
    t.integer("output.deflate_level", &OutputOptions::deflate_level)
        .range(options::between(1, 9))
        .help("zlib level of the GeoTIFFs' deflate compression");
    return t;
  }();
  return table;
}

// splits.preset and its date (GenerateConfig::check_split_preset holds their relations).
void add_split_preset_options(options::Table<GenerateConfig>& t) {
  t.choice("splits.preset", &GenerateConfig::split_preset,
           {{"regions", SplitPreset::kRegions},
            {"before-after", SplitPreset::kBeforeAfter},
            {"map-update", SplitPreset::kMapUpdate}})
      .help(
          "regions: splits by place (the regions above); before-after: train tiles from the scenes captured before "
          "splits.before_after_date, test tiles from those on or after it, over the same streets; map-update: splits "
          "by place, every tile from the scenes on or after splits.before_after_date, its graph the current map's and "
          "beside it the prior map's (splits.prior_maps), every edge with its change label");
  t.text("splits.before_after_date", &GenerateConfig::split_date)
      .help("The date of splits.preset before-after or map-update, YYYY-MM-DD as log.date_captured (\"\" otherwise)");
  t.text("splits.prior_maps", &GenerateConfig::prior_maps)
      .help(
          "splits.preset map-update: the folder of the prior map expansion files, <location>.json (\"\": "
          "<dataroot>/maps/prior/expansion, where a synthetic release with map changes has them)");
}

}  // namespace

const options::Table<GenerateConfig>& generate_option_table() {
  static const options::Table<GenerateConfig> table = [] {
    options::Table<GenerateConfig> t;
    options::schema_version_option(t);
    t.text("dataroot", &GenerateConfig::dataroot)
        .help("nuScenes dataroot (\"\" in a config file: given by --dataroot)");
    t.text("version", &GenerateConfig::version).help("Release version, e.g. v1.0-trainval or v1.0-mini");
    t.shape(
         "locations", "an array of location names", {{"type", "array"}, {"items", {{"type", "string"}}}},
         [](const GenerateConfig& c) { return ordered_json(c.locations); },
         [](GenerateConfig& c, const json& v, const Spec& s) {
           std::vector<std::string> out;
           if (!v.is_array()) options::reject(v, s);
           for (const json& x : v) out.push_back(options::read_string(x, s));
           c.locations = std::move(out);
         })
        .help("Locations to generate, in order ([] = every location with a log in the release)");
    t.shape(
         "scenes.exclude", "an array of {\"name\": scene name, \"reason\": text} ([] keeps every scene)",
         {{"type", "array"},
          {"items",
           {{"type", "object"},
            {"required", {"name", "reason"}},
            {"additionalProperties", false},
            {"properties", {{"name", {{"type", "string"}, {"minLength", 1}}}, {"reason", {{"type", "string"}}}}}}}},
         [](const GenerateConfig& c) {
           ordered_json out = ordered_json::array();
           for (const ExcludedScene& e : c.exclude_scenes) out.push_back({{"name", e.name}, {"reason", e.reason}});
           return out;
         },
         [](GenerateConfig& c, const json& v, const Spec& s) { c.exclude_scenes = read_excluded_scenes(v, s); })
        .help(
            "Scenes left out of the run (default: the real release's known-bad boston-seaport scenes 0499, 0501, "
            "0502, 0515, 0517; [] keeps every scene); the manifest lists those present");
    t.integer("seed", &GenerateConfig::seed).range(options::at_least(0)).help("Seed of every random choice");
    t.number("resolution_m", &GenerateConfig::resolution_m)
        .unit("m")
        .range(options::above_up_to(0, 10))
        .help("Metres per pixel of every layer")
        .then([](GenerateConfig& c) { c.raster.lidar.resolution_m = c.resolution_m; });
    t.include(&GenerateConfig::raster, raster::raster_option_table());
    t.include(&GenerateConfig::graph, graph::lane_graph_option_table());
    t.include(&GenerateConfig::splits, tiling::split_option_table());
    t.shape(
         "splits.regions", "an object: location → array of regions",
         {{"type", "object"},
          {"additionalProperties",
           {{"type", "array"},
            {"items",
             {{"type", "object"},
              {"required", {"name", "split", "bounds_m"}},
              {"additionalProperties", false},
              {"properties",
               {{"name", {{"type", "string"}, {"minLength", 1}}},
                {"split", {{"enum", {"train", "val", "test"}}}},
                {"bounds_m",
                 {{"description", "[x_west, y_south, x_east, y_north] in map metres."},
                  {"type", "array"},
                  {"minItems", 4},
                  {"maxItems", 4},
                  {"items", {{"type", "number"}}}}}}}}}}}},
         [](const GenerateConfig& c) { return regions_json(c.regions); },
         [](GenerateConfig& c, const json& v, const Spec& s) {
           if (!v.is_object()) options::reject(v, s);
           std::map<std::string, std::vector<tiling::Region>> out;
           for (const auto& [location, list] : v.items()) out[location] = read_regions(list, s.key + "." + location);
           c.regions = std::move(out);
         })
        .help("Explicit split regions per location ({} = automatic blocks everywhere)");
    add_split_preset_options(t);
    t.include(&GenerateConfig::crops, tiling::crop_option_table());
    t.include(&GenerateConfig::output, output_option_table());
    t.include(&GenerateConfig::ladder, ladder_option_table());
    return t;
  }();
  return table;
}

ordered_json config_to_json(const GenerateConfig& c) { return generate_option_table().to_json(c); }

ordered_json generate_config_schema() {
  return options::config_schema(
      generate_option_table().specs(), "https://nuscenesgraph.org/schemas/v1/generate-config.schema.json",
      "NuScenesGraph generate config (v1)",
      "Configuration of `nsgraph generate`. A config file may give any subset of the keys (samples/generate.json "
      "lists them all with their defaults); manifest.json stores the resolved config with every key. Generated "
      "from the options' declarations: `nsgraph generate --list-options --format schema`.");
}

void apply_config_json(GenerateConfig& config, const json& doc, const std::string& source, options::Origins* origins) {
  generate_option_table().apply(config, doc, source, origins);
}

GenerateConfig config_from_json(const json& doc, const std::string& file, GenerateConfig base) {
  options::Origins origins;
  apply_config_json(base, doc, file, &origins);
  base.check_relations(origins);
  return base;
}

void apply_config_file(GenerateConfig& config, const std::filesystem::path& file, options::Origins* origins) {
  apply_config_json(config, options::read_config_file(file), file.string(), origins);
}

GenerateConfig load_generate_config(const std::filesystem::path& file) {
  GenerateConfig c;
  options::Origins origins;
  apply_config_file(c, file, &origins);
  c.check_relations(origins);
  return c;
}

GenerateConfig resolve_generate_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                       const std::vector<options::FlagValue>& flags, options::Origins* origins) {
  options::Origins local;
  options::Origins& o = origins ? *origins : local;
  GenerateConfig c =
      options::resolve_config(generate_option_table(), file, settings, flags, "crops.min_lidar_coverage=0.4", o);
  c.check_relations(o);
  return c;
}

}  // namespace nsg::pipeline
