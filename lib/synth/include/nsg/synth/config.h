#pragma once
// The world config of `nsgraph synth` (samples/synth/*.json): everything that shapes the
// synthetic release. Each key is declared once (synth_option_table, nsg/core/options.h):
// reading a file, --set, unknown keys with a "did you mean", range errors naming the key
// and its source, --list-options and schemas/v1/synth-config.schema.json come from there.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/core/options.h"

namespace nsg::synth {

// How the streets are laid out: a Manhattan grid inside a ring road, or the organic city
// (curved arterials, skewed, T and Y junctions, a roundabout, lane drops, turn pockets, a
// divided boulevard with a ramp; docs/synthetic-release.md) in the same rectangle.
enum class CityLayout { kGrid, kOrganic };

struct CityConfig {
  CityLayout layout = CityLayout::kGrid;
  // The organic layout's local streets between its arterials (more junctions and lanes in
  // the same rectangle; needs at least 700 × 400 m). Off keeps earlier organic worlds as they were.
  bool local_streets = false;
  std::array<double, 2> origin_m{200.0, 200.0};  // south-west corner of the street grid
  int blocks_x = 2;                              // blocks between the grid's streets
  int blocks_y = 2;
  double block_size_m = 90.0;  // street centre to street centre
  double lane_width_m = 3.5;
  int max_lanes_per_direction = 2;     // 1..3
  double one_way_fraction = 0.25;      // of interior streets
  double parking_fraction = 0.5;       // streets with a parking strip along both curbs
  double ring_corner_radius_m = 30.0;  // the perimeter ring road's rounded corners
  double sidewalk_width_m = 3.0;
  double park_fraction = 0.2;        // blocks that are parks (vegetation, no buildings)
  double ground_resolution_m = 0.1;  // cell size of the ground material raster
};

struct TrafficConfig {
  int moving_vehicles_per_scene = 12;
  double parked_spacing_m = 7.0;  // mean distance between parked cars along a strip
  double parked_occupancy = 0.6;  // fraction of parking slots taken
  int pedestrians_per_scene = 10;
  double annotation_range_m = 50.0;  // objects annotated within this distance of the ego
};

struct ScenesConfig {
  int count = 2;
  int samples_per_scene = 6;  // key frames (2 Hz) per scene
  double ego_speed_mps = 8.0;
  int64_t first_timestamp_us = 1532402927647951;
  // Capture days the scenes are spread over, in index order (scene i on day
  // floor(i · days / count)), so logs carry several dates for time-ordered questions
  // (docs/synthetic-release.md); 1 = all on the first day.
  int capture_days = 1;
};

struct LidarConfig {
  double rate_hz = 20.0;
  int beams = 32;
  int points_per_sweep = 34720;
  int roof_points = 8000;
  double max_range_m = 100.0;
  double range_noise_m = 0.02;
  // nuScenes-lidarseg for every key-frame sweep: lidarseg.json and one
  // lidarseg/<version>/<sd_token>_lidarseg.bin of per-point labels (the ray caster's hit).
  bool lidarseg = true;
};

struct CameraConfig {
  double rate_hz = 12.0;
  // A subset of the six CAM_* channels, in the real sensor table's order by default.
  std::vector<std::string> channels = {"CAM_FRONT", "CAM_FRONT_RIGHT", "CAM_FRONT_LEFT",
                                       "CAM_BACK",  "CAM_BACK_LEFT",   "CAM_BACK_RIGHT"};
  int width_px = 1600;
  int height_px = 900;
  int jpeg_quality = 80;
  double label_noise_rate = 0.0;
  // Class masks at 1/n of the image's size (sides rounded up; pixel k = the class at full
  // pixel k·n): 2 is what `segment` writes by default and what generate samples at.
  int mask_scale_denom = 1;
};

struct DetectionsConfig {
  std::string name = "synthetic_detector";  // file name under <dataroot>/detections/
  double position_noise_m = 0.3;
  double yaw_noise_rad = 0.05;
  double miss_rate = 0.1;
  double false_positives_per_sample = 0.5;
  double score_true_mean = 0.75;  // scores of true positives ~ N(mean, 0.1) clamped
  double score_false_mean = 0.3;  // scores of false positives
};

// Seeded atomic edits of the map from a capture day on (docs/synthetic-release.md "Map
// changes"): the scenes captured on or after `from_day` are rendered in the changed world,
// the release carries the map before (maps/prior/expansion/) and after (maps/expansion/),
// and changes.json lists every edit with its tokens. No edit (every count 0) = no change:
// the release is byte-identical to one without the key.
struct ChangesConfig {
  int from_day = 1;          // capture day (scenes.capture_days' index) of the first changed scene
  int crossings_added = 0;   // mid-block pedestrian crossings painted and mapped
  int turns_removed = 0;     // turning connectors taken out of the map; traffic no longer turns there
  int lanes_closed = 0;      // lanes removed from the map, barriers along them
  int turns_added = 0;       // turning connectors a junction did not have, mapped and driven
  int dividers_retyped = 0;  // dashed dividers between two lanes a way made solid, paint and map
  bool any() const { return crossings_added + turns_removed + lanes_closed + turns_added + dividers_retyped > 0; }
};

struct SynthConfig {
  std::string location = "boston-seaport";
  std::string version = "v1.0-mini";
  std::array<double, 2> map_size_m{700.0, 700.0};  // canvas_edge of the synthetic map
  uint64_t seed = 0;
  CityConfig city;
  TrafficConfig traffic;
  ScenesConfig scenes;
  LidarConfig lidar;
  CameraConfig camera;
  DetectionsConfig detections;
  ChangesConfig changes;

  bool right_hand_traffic() const { return location == "boston-seaport"; }
  // Every value through its declaration, then the checks across keys; ConfigError naming
  // the key.
  void validate() const;
  // The checks across keys (the street grid fits its blocks and the map, the roof points
  // fit the sweep); ConfigError naming the key and the source that set it (`origins`).
  void check_relations(const options::Origins& origins = {}) const;
  // Parses JSON text; `file` names the source in errors.
  static SynthConfig from_json_text(const std::string& text, const std::string& file);
  static SynthConfig from_file(const std::filesystem::path& path);
};

// The declaration of every key of a world config.
const options::Table<SynthConfig>& synth_option_table();
// The JSON Schema of a world config (schemas/v1/synth-config.schema.json).
options::OrderedJson synth_config_schema();
// options::resolve_config's precedence (the defaults, the file, each --set "key=value",
// then the flags), then the checks across keys. Errors name the key and the file, --set or
// flag it came from.
SynthConfig resolve_synth_config(const std::filesystem::path& file, const std::vector<std::string>& settings,
                                 const std::vector<options::FlagValue>& flags = {},
                                 options::Origins* origins = nullptr);

// The six camera channels in the order of the real sensor table.
const std::vector<std::string>& all_camera_channels();

}  // namespace nsg::synth
