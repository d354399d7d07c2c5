// SynthConfig: each key declared once (key, type, unit, range, description); reading,
// --set, listings and the schema come from the declarations. The checks across keys
// (the street grid's geometry) run after every key is read.
#include "nsg/synth/config.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"

namespace nsg::synth {
namespace {

using options::Json;
using options::OrderedJson;
using options::Range;
using options::Spec;
using options::Table;

// A pair of numbers [a, b], each in `range` (unit in the spec).
template <typename Owner>
options::Option<Owner>& number_pair(Table<Owner>& t, std::string key, std::array<double, 2> Owner::*field,
                                    const Range& range, const std::string& what) {
  Spec item;
  item.type = "number";
  item.range = range;
  OrderedJson items = item.schema();
  items.erase("description");
  const std::string in = range.describe();
  return t.shape(
      std::move(key), what + (in.empty() ? "" : ", each " + in),
      {{"type", "array"}, {"minItems", 2}, {"maxItems", 2}, {"items", items}},
      [field](const Owner& o) { return OrderedJson(o.*field); },
      [field, range](Owner& o, const Json& v, const Spec& s) {
        if (!v.is_array() || v.size() != 2) options::reject(v, s);
        std::array<double, 2> out{};
        for (size_t i = 0; i < 2; ++i) {
          if (!v[i].is_number() || !std::isfinite(v[i].get<double>()) || !range.contains(v[i].get<double>()))
            options::reject(v, s);
          out[i] = v[i].get<double>();
        }
        o.*field = out;
      });
}

// A string matching `pattern` (JSON Schema) whose check is `ok`.
template <typename Owner>
options::Option<Owner>& checked_text(Table<Owner>& t, std::string key, std::string Owner::*field,
                                     const std::string& expected, const std::string& pattern,
                                     bool (*ok)(const std::string&)) {
  return t.shape(
      std::move(key), expected, {{"type", "string"}, {"pattern", pattern}},
      [field](const Owner& o) { return OrderedJson(o.*field); },
      [field, ok](Owner& o, const Json& v, const Spec& s) {
        const std::string text = options::read_string(v, s);
        if (!ok(text)) options::reject(v, s);
        o.*field = text;
      });
}

bool is_release_name(const std::string& v) {
  return v.rfind("v1.0-", 0) == 0 && v.size() > 5 && v.find_first_of("/\\") == std::string::npos;
}
bool is_plain_file_name(const std::string& v) {
  return !v.empty() && v.find_first_of("/\\") == std::string::npos && v[0] != '.';
}

const Table<CityConfig>& city_table() {
  static const Table<CityConfig> table = [] {
    Table<CityConfig> t;
    t.choice("city.layout", &CityConfig::layout,
             std::vector<std::pair<std::string, CityLayout>>{{"grid", CityLayout::kGrid},
                                                             {"organic", CityLayout::kOrganic}})
        .help(
            "Street layout: a grid inside a ring road, or the organic city in the same rectangle "
            "(blocks · block_size_m from origin_m)");
    t.boolean("city.local_streets", &CityConfig::local_streets)
        .help(
            "The organic layout's local streets between its arterials: ten more junctions (T, skewed "
            "crossings) in the same rectangle, at least 700 × 400 m");
    number_pair(t, "city.origin_m", &CityConfig::origin_m, Range{}, "[x, y] in metres")
        .unit("m")
        .help("South-west corner of the street grid (at least sidewalk + 20 m inside the map)");
    t.integer("city.blocks_x", &CityConfig::blocks_x).range(options::between(2, 40)).help("Blocks west to east");
    t.integer("city.blocks_y", &CityConfig::blocks_y).range(options::between(2, 40)).help("Blocks south to north");
    t.number("city.block_size_m", &CityConfig::block_size_m)
        .unit("m")
        .range(options::above_up_to(0, 500))
        .help("Street centre to street centre (at least 2·(lanes·width + parking + sidewalk) + 30 m)");
    t.number("city.lane_width_m", &CityConfig::lane_width_m)
        .unit("m")
        .range(options::between(2.5, 5))
        .help("Width of a lane");
    t.integer("city.max_lanes_per_direction", &CityConfig::max_lanes_per_direction)
        .range(options::one_of({1, 2, 3}))
        .help("Most lanes a street has in one direction");
    t.number("city.one_way_fraction", &CityConfig::one_way_fraction)
        .range(options::between(0, 1))
        .help("Fraction of interior streets that are one-way");
    t.number("city.parking_fraction", &CityConfig::parking_fraction)
        .range(options::between(0, 1))
        .help("Fraction of streets with a parking strip along both curbs");
    t.number("city.ring_corner_radius_m", &CityConfig::ring_corner_radius_m)
        .unit("m")
        .range(options::above(0))
        .help("Radius of the perimeter ring road's corners (> road half-width + sidewalk + 5 m, ≤ block_size_m / 2)");
    t.number("city.sidewalk_width_m", &CityConfig::sidewalk_width_m)
        .unit("m")
        .range(options::between(1, 8))
        .help("Width of a sidewalk");
    t.number("city.park_fraction", &CityConfig::park_fraction)
        .range(options::between(0, 1))
        .help("Fraction of blocks that are parks (vegetation, no buildings)");
    t.number("city.ground_resolution_m", &CityConfig::ground_resolution_m)
        .unit("m")
        .range(options::between(0.02, 0.2))
        .help("Cell size of the ground material raster");
    return t;
  }();
  return table;
}

const Table<TrafficConfig>& traffic_table() {
  static const Table<TrafficConfig> table = [] {
    Table<TrafficConfig> t;
    t.integer("traffic.moving_vehicles_per_scene", &TrafficConfig::moving_vehicles_per_scene)
        .range(options::between(0, 500))
        .help("Vehicles driving in each scene");
    t.number("traffic.parked_spacing_m", &TrafficConfig::parked_spacing_m)
        .unit("m")
        .range(options::between(5, 100))
        .help("Distance between parking slots along a strip");
    t.number("traffic.parked_occupancy", &TrafficConfig::parked_occupancy)
        .range(options::between(0, 1))
        .help("Fraction of parking slots taken");
    t.integer("traffic.pedestrians_per_scene", &TrafficConfig::pedestrians_per_scene)
        .range(options::between(0, 500))
        .help("Pedestrians in each scene");
    t.number("traffic.annotation_range_m", &TrafficConfig::annotation_range_m)
        .unit("m")
        .range(options::above_up_to(0, 200))
        .help("Objects are annotated within this distance of the ego");
    return t;
  }();
  return table;
}

const Table<ScenesConfig>& scenes_table() {
  static const Table<ScenesConfig> table = [] {
    Table<ScenesConfig> t;
    t.integer("scenes.count", &ScenesConfig::count).range(options::between(1, 1000)).help("Scenes in the release");
    t.integer("scenes.samples_per_scene", &ScenesConfig::samples_per_scene)
        .range(options::between(2, 100))
        .help("Key frames (2 Hz) per scene");
    t.number("scenes.ego_speed_mps", &ScenesConfig::ego_speed_mps)
        .unit("m/s")
        .range(options::between(0.5, 30))
        .help("Speed of the ego vehicle");
    t.integer("scenes.first_timestamp_us", &ScenesConfig::first_timestamp_us)
        .unit("µs")
        .range(Range{1e15, 4e15, true, true, {}})
        .help("Time of the first sample, microseconds since the Unix epoch (2001..2096)");
    t.integer("scenes.capture_days", &ScenesConfig::capture_days)
        .range(options::between(1, 365))
        .help("Days the scenes are spread over in index order (scene i on day floor(i * days / count)); 1 = one day");
    return t;
  }();
  return table;
}

const Table<LidarConfig>& lidar_table() {
  static const Table<LidarConfig> table = [] {
    Table<LidarConfig> t;
    std::vector<double> even_rates;
    for (int hz = 2; hz <= 40; hz += 2) even_rates.push_back(hz);
    t.number("lidar.rate_hz", &LidarConfig::rate_hz)
        .unit("Hz")
        .range(options::one_of(even_rates))
        .help("Sweep rate: even, so key frames (2 Hz) are every rate/2-th sweep");
    t.integer("lidar.beams", &LidarConfig::beams).range(options::between(1, 128)).help("Laser beams");
    t.integer("lidar.points_per_sweep", &LidarConfig::points_per_sweep)
        .range(options::between(100, 500000))
        .help("Points in one sweep");
    t.integer("lidar.roof_points", &LidarConfig::roof_points)
        .range(options::at_least(0))
        .help("Of those, points that hit the ego's roof (< points_per_sweep)");
    t.number("lidar.max_range_m", &LidarConfig::max_range_m)
        .unit("m")
        .range(options::above_up_to(5, 300))
        .help("Farthest return");
    t.number("lidar.range_noise_m", &LidarConfig::range_noise_m)
        .unit("m")
        .range(options::between(0, 1))
        .help("Standard deviation of the range noise");
    t.boolean("lidar.lidarseg", &LidarConfig::lidarseg)
        .help("Write nuScenes-lidarseg labels (the ray caster's hit) for every key-frame sweep");
    return t;
  }();
  return table;
}

const Table<CameraConfig>& camera_table() {
  static const Table<CameraConfig> table = [] {
    Table<CameraConfig> t;
    t.number("camera.rate_hz", &CameraConfig::rate_hz)
        .unit("Hz")
        .range(options::between(2, 30))
        .help("Frame rate of each camera");
    t.shape(
         "camera.channels", "distinct camera channel names (CAM_FRONT, ...)",
         {{"type", "array"}, {"uniqueItems", true}, {"items", {{"enum", all_camera_channels()}}}},
         [](const CameraConfig& c) { return OrderedJson(c.channels); },
         [](CameraConfig& c, const Json& v, const Spec& s) {
           if (!v.is_array()) options::reject(v, s);
           const std::vector<std::string>& all = all_camera_channels();
           std::vector<std::string> out;
           for (const Json& x : v) {
             if (!x.is_string() || std::find(all.begin(), all.end(), x.get<std::string>()) == all.end() ||
                 std::find(out.begin(), out.end(), x.get<std::string>()) != out.end())
               options::reject(v, s);
             out.push_back(x.get<std::string>());
           }
           c.channels = std::move(out);
         })
        .help("Cameras written, a subset of the six");
    t.integer("camera.width_px", &CameraConfig::width_px)
        .unit("px")
        .range(options::between(16, 4096))
        .help("Image width");
    t.integer("camera.height_px", &CameraConfig::height_px)
        .unit("px")
        .range(options::between(16, 4096))
        .help("Image height");
    t.integer("camera.jpeg_quality", &CameraConfig::jpeg_quality)
        .range(options::between(1, 100))
        .help("JPEG quality of the images");
    t.number("camera.label_noise_rate", &CameraConfig::label_noise_rate)
        .range(options::between(0, 1))
        .help("Fraction of class-mask pixels given a wrong class");
    t.integer("camera.mask_scale_denom", &CameraConfig::mask_scale_denom)
        .range(options::between(1, 8))
        .help("Class masks at 1/n of the image's size (sides rounded up)");
    return t;
  }();
  return table;
}

const Table<DetectionsConfig>& detections_table() {
  static const Table<DetectionsConfig> table = [] {
    Table<DetectionsConfig> t;
    checked_text(t, "detections.name", &DetectionsConfig::name, "a plain file name (no '/', not starting with '.')",
                 "^[^./\\\\][^/\\\\]*$", &is_plain_file_name)
        .help("File name under <dataroot>/detections/");
    t.number("detections.position_noise_m", &DetectionsConfig::position_noise_m)
        .unit("m")
        .range(options::between(0, 10))
        .help("Standard deviation of a detection's position error");
    t.number("detections.yaw_noise_rad", &DetectionsConfig::yaw_noise_rad)
        .unit("rad")
        .range(options::between(0, 3.2))
        .help("Standard deviation of a detection's heading error");
    t.number("detections.miss_rate", &DetectionsConfig::miss_rate)
        .range(options::between(0, 1))
        .help("Fraction of objects not detected");
    t.number("detections.false_positives_per_sample", &DetectionsConfig::false_positives_per_sample)
        .range(options::between(0, 100))
        .help("Mean false detections per sample");
    t.number("detections.score_true_mean", &DetectionsConfig::score_true_mean)
        .range(options::between(0, 1))
        .help("Mean score of true detections (~ N(mean, 0.1), clamped)");
    t.number("detections.score_false_mean", &DetectionsConfig::score_false_mean)
        .range(options::between(0, 1))
        .help("Mean score of false detections");
    return t;
  }();
  return table;
}

const Table<ChangesConfig>& changes_table() {
  static const Table<ChangesConfig> table = [] {
    Table<ChangesConfig> t;
    t.integer("changes.from_day", &ChangesConfig::from_day)
        .range(options::between(1, 364))
        .help(
            "Capture day of the first scene in the changed world (1 .. scenes.capture_days - 1; scene i is on day "
            "floor(i * days / count))");
    t.integer("changes.crossings_added", &ChangesConfig::crossings_added)
        .range(options::between(0, 100))
        .help("Mid-block pedestrian crossings added from changes.from_day on (painted and mapped)");
    t.integer("changes.turns_removed", &ChangesConfig::turns_removed)
        .range(options::between(0, 100))
        .help("Turning lane connectors removed from changes.from_day on (traffic no longer turns there)");
    t.integer("changes.lanes_closed", &ChangesConfig::lanes_closed)
        .range(options::between(0, 100))
        .help(
            "Lanes closed from changes.from_day on: removed from the map with their connectors, barriers along "
            "them");
    t.integer("changes.turns_added", &ChangesConfig::turns_added)
        .range(options::between(0, 100))
        .help("Turning lane connectors a junction did not have, added from changes.from_day on (mapped, driven)");
    t.integer("changes.dividers_retyped", &ChangesConfig::dividers_retyped)
        .range(options::between(0, 100))
        .help(
            "Dashed lane dividers between the two lanes of a direction made solid from changes.from_day on (paint "
            "and map)");
    return t;
  }();
  return table;
}

// The checks across keys; ConfigError("", key, expected).
void check_geometry(const SynthConfig& c) {
  const CityConfig& city = c.city;
  // A block must hold two full-width streets' halves, sidewalks and the corner arcs.
  const double max_half_road = city.max_lanes_per_direction * city.lane_width_m + 2.5;
  NSG_CHECK(city.block_size_m >= 2.0 * (max_half_road + city.sidewalk_width_m) + 30.0, ConfigError, "",
            "city.block_size_m", "at least 2·(lanes·width + parking + sidewalk) + 30 m and at most 500 m");
  NSG_CHECK(city.ring_corner_radius_m >= max_half_road + city.sidewalk_width_m + 5.0 &&
                city.ring_corner_radius_m <= city.block_size_m / 2.0,
            ConfigError, "", "city.ring_corner_radius_m",
            "a radius larger than the road half-width + sidewalk + 5 m and ≤ block_size/2");
  if (city.layout == CityLayout::kOrganic) {
    // The organic plan has two-lane roads and needs room for its roundabout, bends and ramp.
    const double w = city.blocks_x * city.block_size_m, h = city.blocks_y * city.block_size_m;
    NSG_CHECK(city.max_lanes_per_direction >= 2, ConfigError, "", "city.max_lanes_per_direction",
              "2 or 3 for the organic layout (its lane drop and boulevard have two lanes a way)");
    NSG_CHECK(h >= 300.0, ConfigError, "", "city.blocks_y",
              "blocks_y · block_size_m of at least 300 m for the organic layout");
    NSG_CHECK(w >= 1.2 * h && w <= 3.0 * h, ConfigError, "", "city.blocks_x",
              "blocks_x · block_size_m between 1.2 and 3 times blocks_y · block_size_m for the organic layout");
  }
  if (city.local_streets) {
    const double w = city.blocks_x * city.block_size_m, h = city.blocks_y * city.block_size_m;
    NSG_CHECK(city.layout == CityLayout::kOrganic, ConfigError, "", "city.local_streets",
              "false unless city.layout is \"organic\" (the grid has its own streets)");
    NSG_CHECK(w >= 700.0 && h >= 400.0, ConfigError, "", "city.local_streets",
              "false, or a rectangle of at least 700 × 400 m (blocks · block_size_m) to hold the local streets");
  }
  NSG_CHECK(!c.changes.any() || c.changes.from_day < c.scenes.capture_days, ConfigError, "", "changes.from_day",
            "a capture day before scenes.capture_days (scenes on earlier days see the map before the changes)");
  NSG_CHECK(c.lidar.roof_points < c.lidar.points_per_sweep, ConfigError, "", "lidar.roof_points",
            "an integer in [0, points_per_sweep)");
  const double margin = city.sidewalk_width_m + 20.0;
  NSG_CHECK(city.origin_m[0] >= margin && city.origin_m[1] >= margin, ConfigError, "", "city.origin_m",
            "a grid origin at least sidewalk + 20 m inside the map");
  NSG_CHECK(city.origin_m[0] + city.blocks_x * city.block_size_m + margin <= c.map_size_m[0] &&
                city.origin_m[1] + city.blocks_y * city.block_size_m + margin <= c.map_size_m[1],
            ConfigError, "", "map_size_m", "a map large enough for the street grid plus a 20 m margin");
}

}  // namespace

const std::vector<std::string>& all_camera_channels() {
  static const std::vector<std::string> kChannels = CameraConfig{}.channels;
  return kChannels;
}

const Table<SynthConfig>& synth_option_table() {
  static const Table<SynthConfig> table = [] {
    Table<SynthConfig> t;
    options::schema_version_option(t);
    t.choice("location", &SynthConfig::location,
             std::vector<std::pair<std::string, std::string>>{{"singapore-onenorth", "singapore-onenorth"},
                                                              {"singapore-hollandvillage", "singapore-hollandvillage"},
                                                              {"singapore-queenstown", "singapore-queenstown"},
                                                              {"boston-seaport", "boston-seaport"}})
        .help("nuScenes map the release claims (boston-seaport drives on the right)");
    checked_text(t, "version", &SynthConfig::version, "a release name like \"v1.0-mini\"", "^v1\\.0-[^/\\\\]+$",
                 &is_release_name)
        .help("Release version (the folder of the tables)");
    number_pair(t, "map_size_m", &SynthConfig::map_size_m, options::between(100, 4000), "[width, height] in metres")
        .unit("m")
        .help("Size of the synthetic map (its canvas_edge)");
    t.integer("seed", &SynthConfig::seed).range(options::at_least(0)).help("Seed of every random choice (--seed)");
    t.include(&SynthConfig::city, city_table());
    t.include(&SynthConfig::traffic, traffic_table());
    t.include(&SynthConfig::scenes, scenes_table());
    t.include(&SynthConfig::lidar, lidar_table());
    t.include(&SynthConfig::camera, camera_table());
    t.include(&SynthConfig::detections, detections_table());
    t.include(&SynthConfig::changes, changes_table());
    return t;
  }();
  return table;
}

options::OrderedJson synth_config_schema() {
  return options::config_schema(
      synth_option_table().specs(), "https://nuscenesgraph.org/schemas/v1/synth-config.schema.json",
      "NuScenesGraph synthetic world config (v1)",
      "World config of `nsgraph synth` (samples/synth/*.json). A file may give any subset of the keys; the others "
      "keep their defaults. Generated from the options' declarations: `nsgraph synth --list-options --format "
      "schema`.");
}

void SynthConfig::check_relations(const options::Origins& origins) const {
  try {
    check_geometry(*this);
  } catch (const ConfigError& e) {
    options::rethrow_from_origin(e, origins);
  }
}

void SynthConfig::validate() const {
  synth_option_table().check(*this);
  check_geometry(*this);
}

SynthConfig SynthConfig::from_json_text(const std::string& text, const std::string& file) {
  SynthConfig c;
  options::Origins origins;
  synth_option_table().apply(c, options::parse_config_text(text, file), file, &origins);
  c.check_relations(origins);
  return c;
}

SynthConfig SynthConfig::from_file(const std::filesystem::path& path) {
  return from_json_text(read_file(path), path.string());
}

SynthConfig resolve_synth_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                 const std::vector<options::FlagValue>& flags, options::Origins* origins) {
  options::Origins local;
  options::Origins& o = origins ? *origins : local;
  SynthConfig c = options::resolve_config(synth_option_table(), file, settings, flags, "scenes.count=3", o);
  c.check_relations(o);
  return c;
}

}  // namespace nsg::synth
