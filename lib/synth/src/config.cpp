// SynthConfig: strict JSON parsing (unknown keys are errors naming the key) and checks.
#include "nsg/synth/config.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"

namespace nsg::synth {
namespace {

using nlohmann::json;

const std::vector<std::string> kLocations = {"singapore-onenorth", "singapore-hollandvillage", "singapore-queenstown",
                                             "boston-seaport"};

void require(bool cond, const std::string& key, const std::string& expected) {
  if (!cond) throw ConfigError("synth config", key, expected);
}

// Reads the members of one JSON object into typed fields, rejecting unknown keys.
class ObjectReader {
 public:
  ObjectReader(const json& obj, std::string path, std::string file)
      : obj_(obj), path_(std::move(path)), file_(std::move(file)) {
    if (!obj_.is_object()) throw ConfigError(file_, path_.empty() ? "<root>" : path_, "a JSON object");
  }
  std::string key(const std::string& name) const { return path_.empty() ? name : path_ + "." + name; }

  template <typename T>
  void get(const std::string& name, T& out) {
    known_.insert(name);
    auto it = obj_.find(name);
    if (it == obj_.end()) return;
    try {
      if constexpr (std::is_same_v<T, bool>) {
        if (!it->is_boolean()) throw std::invalid_argument("boolean");
        out = it->template get<bool>();
      } else if constexpr (std::is_same_v<T, double>) {
        if (!it->is_number()) throw std::invalid_argument("number");
        out = it->template get<double>();
        if (!std::isfinite(out)) throw std::invalid_argument("number");
      } else if constexpr (std::is_integral_v<T>) {
        if (!it->is_number_integer() || (std::is_unsigned_v<T> && !it->is_number_unsigned()))
          throw std::invalid_argument("integer");
        out = it->template get<T>();
      } else {
        out = it->template get<T>();
      }
    } catch (const std::exception&) {
      throw ConfigError(file_, key(name), std::string("a value of the right type (got ") + it->dump() + ")");
    }
  }
  const json* child(const std::string& name) {
    known_.insert(name);
    auto it = obj_.find(name);
    return it == obj_.end() ? nullptr : &*it;
  }
  void finish() const {
    for (auto it = obj_.begin(); it != obj_.end(); ++it) {
      if (!known_.count(it.key())) throw ConfigError(file_, key(it.key()), "a known key (unknown key)");
    }
  }

 private:
  const json& obj_;
  std::string path_;
  std::string file_;
  std::set<std::string> known_;
};

}  // namespace

const std::vector<std::string>& all_camera_channels() {
  static const std::vector<std::string> kChannels = {"CAM_FRONT", "CAM_FRONT_RIGHT", "CAM_FRONT_LEFT",
                                                     "CAM_BACK",  "CAM_BACK_LEFT",   "CAM_BACK_RIGHT"};
  return kChannels;
}

void CityConfig::validate() const {
  require(blocks_x >= 2 && blocks_x <= 40, "city.blocks_x", "an integer in [2, 40]");
  require(blocks_y >= 2 && blocks_y <= 40, "city.blocks_y", "an integer in [2, 40]");
  require(lane_width_m >= 2.5 && lane_width_m <= 5.0, "city.lane_width_m", "a width in [2.5, 5] m");
  require(max_lanes_per_direction >= 1 && max_lanes_per_direction <= 3, "city.max_lanes_per_direction", "1, 2 or 3");
  // A block must hold two full-width streets' halves, sidewalks and the corner arcs.
  const double max_half_road = max_lanes_per_direction * lane_width_m + 2.5;
  require(block_size_m >= 2.0 * (max_half_road + sidewalk_width_m) + 30.0 && block_size_m <= 500.0, "city.block_size_m",
          "at least 2·(lanes·width + parking + sidewalk) + 30 m and at most 500 m");
  require(one_way_fraction >= 0.0 && one_way_fraction <= 1.0, "city.one_way_fraction", "a fraction in [0, 1]");
  require(parking_fraction >= 0.0 && parking_fraction <= 1.0, "city.parking_fraction", "a fraction in [0, 1]");
  require(park_fraction >= 0.0 && park_fraction <= 1.0, "city.park_fraction", "a fraction in [0, 1]");
  require(ring_corner_radius_m >= max_half_road + sidewalk_width_m + 5.0 && ring_corner_radius_m <= block_size_m / 2.0,
          "city.ring_corner_radius_m", "a radius larger than the road half-width + sidewalk + 5 m and ≤ block_size/2");
  require(sidewalk_width_m >= 1.0 && sidewalk_width_m <= 8.0, "city.sidewalk_width_m", "a width in [1, 8] m");
  require(ground_resolution_m >= 0.02 && ground_resolution_m <= 0.2, "city.ground_resolution_m",
          "a cell size in [0.02, 0.2] m");
}

void TrafficConfig::validate() const {
  require(moving_vehicles_per_scene >= 0 && moving_vehicles_per_scene <= 500, "traffic.moving_vehicles_per_scene",
          "an integer in [0, 500]");
  require(parked_spacing_m >= 5.0 && parked_spacing_m <= 100.0, "traffic.parked_spacing_m", "a spacing in [5, 100] m");
  require(parked_occupancy >= 0.0 && parked_occupancy <= 1.0, "traffic.parked_occupancy", "a fraction in [0, 1]");
  require(pedestrians_per_scene >= 0 && pedestrians_per_scene <= 500, "traffic.pedestrians_per_scene",
          "an integer in [0, 500]");
  require(annotation_range_m > 0.0 && annotation_range_m <= 200.0, "traffic.annotation_range_m",
          "a range in (0, 200] m");
}

void ScenesConfig::validate() const {
  require(count >= 1 && count <= 1000, "scenes.count", "an integer in [1, 1000]");
  require(samples_per_scene >= 2 && samples_per_scene <= 100, "scenes.samples_per_scene", "an integer in [2, 100]");
  require(ego_speed_mps >= 0.5 && ego_speed_mps <= 30.0, "scenes.ego_speed_mps", "a speed in [0.5, 30] m/s");
  require(first_timestamp_us > 1000000000000000LL && first_timestamp_us < 4000000000000000LL,
          "scenes.first_timestamp_us", "microseconds since the Unix epoch (2001..2096)");
}

void LidarConfig::validate() const {
  require(rate_hz >= 2.0 && rate_hz <= 40.0 && std::fmod(rate_hz, 2.0) == 0.0, "lidar.rate_hz",
          "an even rate in [2, 40] Hz (key frames are every rate/2-th sweep)");
  require(beams >= 1 && beams <= 128, "lidar.beams", "an integer in [1, 128]");
  require(points_per_sweep >= 100 && points_per_sweep <= 500000, "lidar.points_per_sweep",
          "an integer in [100, 500000]");
  require(roof_points >= 0 && roof_points < points_per_sweep, "lidar.roof_points",
          "an integer in [0, points_per_sweep)");
  require(max_range_m > 5.0 && max_range_m <= 300.0, "lidar.max_range_m", "a range in (5, 300] m");
  require(range_noise_m >= 0.0 && range_noise_m <= 1.0, "lidar.range_noise_m", "a noise in [0, 1] m");
}

void CameraConfig::validate() const {
  require(rate_hz >= 2.0 && rate_hz <= 30.0, "camera.rate_hz", "a rate in [2, 30] Hz");
  std::set<std::string> seen;
  for (const auto& c : channels) {
    const auto& all = all_camera_channels();
    require(std::find(all.begin(), all.end(), c) != all.end(), "camera.channels",
            "camera channel names (CAM_FRONT, …), got \"" + c + "\"");
    require(seen.insert(c).second, "camera.channels", "distinct channels, \"" + c + "\" repeated");
  }
  require(width_px >= 16 && width_px <= 4096, "camera.width_px", "an integer in [16, 4096]");
  require(height_px >= 16 && height_px <= 4096, "camera.height_px", "an integer in [16, 4096]");
  require(jpeg_quality >= 1 && jpeg_quality <= 100, "camera.jpeg_quality", "an integer in [1, 100]");
  require(label_noise_rate >= 0.0 && label_noise_rate <= 1.0, "camera.label_noise_rate", "a fraction in [0, 1]");
  require(mask_scale_denom >= 1 && mask_scale_denom <= 8, "camera.mask_scale_denom", "an integer in [1, 8]");
}

void DetectionsConfig::validate() const {
  require(!name.empty() && name.find_first_of("/\\") == std::string::npos && name[0] != '.', "detections.name",
          "a plain file name");
  require(position_noise_m >= 0.0 && position_noise_m <= 10.0, "detections.position_noise_m", "a noise in [0, 10] m");
  require(yaw_noise_rad >= 0.0 && yaw_noise_rad <= 3.2, "detections.yaw_noise_rad", "a noise in [0, π] rad");
  require(miss_rate >= 0.0 && miss_rate <= 1.0, "detections.miss_rate", "a fraction in [0, 1]");
  require(false_positives_per_sample >= 0.0 && false_positives_per_sample <= 100.0,
          "detections.false_positives_per_sample", "a rate in [0, 100]");
  require(score_true_mean >= 0.0 && score_true_mean <= 1.0, "detections.score_true_mean", "a score in [0, 1]");
  require(score_false_mean >= 0.0 && score_false_mean <= 1.0, "detections.score_false_mean", "a score in [0, 1]");
}

void SynthConfig::validate() const {
  require(std::find(kLocations.begin(), kLocations.end(), location) != kLocations.end(), "location",
          "one of singapore-onenorth, singapore-hollandvillage, singapore-queenstown, boston-seaport");
  require(version.rfind("v1.0-", 0) == 0 && version.size() > 5 && version.find_first_of("/\\") == std::string::npos,
          "version", "a release name like \"v1.0-mini\"");
  require(map_size_m[0] >= 100.0 && map_size_m[0] <= 4000.0 && map_size_m[1] >= 100.0 && map_size_m[1] <= 4000.0,
          "map_size_m", "[width, height] in [100, 4000] m");
  city.validate();
  traffic.validate();
  scenes.validate();
  lidar.validate();
  camera.validate();
  detections.validate();
  const double margin = city.sidewalk_width_m + 20.0;
  require(city.origin_m[0] >= margin && city.origin_m[1] >= margin, "city.origin_m",
          "a grid origin at least sidewalk + 20 m inside the map");
  require(city.origin_m[0] + city.blocks_x * city.block_size_m + margin <= map_size_m[0] &&
              city.origin_m[1] + city.blocks_y * city.block_size_m + margin <= map_size_m[1],
          "map_size_m", "a map large enough for the street grid plus a 20 m margin");
}

SynthConfig SynthConfig::from_json_text(const std::string& text, const std::string& file) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    throw ParseError(file, "", std::string("valid JSON (") + e.what() + ")");
  }
  SynthConfig c;
  c.camera.channels = all_camera_channels();
  ObjectReader r(root, "", file);
  r.get("location", c.location);
  r.get("version", c.version);
  r.get("map_size_m", c.map_size_m);
  r.get("seed", c.seed);
  if (const json* j = r.child("city")) {
    ObjectReader s(*j, "city", file);
    s.get("origin_m", c.city.origin_m);
    s.get("blocks_x", c.city.blocks_x);
    s.get("blocks_y", c.city.blocks_y);
    s.get("block_size_m", c.city.block_size_m);
    s.get("lane_width_m", c.city.lane_width_m);
    s.get("max_lanes_per_direction", c.city.max_lanes_per_direction);
    s.get("one_way_fraction", c.city.one_way_fraction);
    s.get("parking_fraction", c.city.parking_fraction);
    s.get("ring_corner_radius_m", c.city.ring_corner_radius_m);
    s.get("sidewalk_width_m", c.city.sidewalk_width_m);
    s.get("park_fraction", c.city.park_fraction);
    s.get("ground_resolution_m", c.city.ground_resolution_m);
    s.finish();
  }
  if (const json* j = r.child("traffic")) {
    ObjectReader s(*j, "traffic", file);
    s.get("moving_vehicles_per_scene", c.traffic.moving_vehicles_per_scene);
    s.get("parked_spacing_m", c.traffic.parked_spacing_m);
    s.get("parked_occupancy", c.traffic.parked_occupancy);
    s.get("pedestrians_per_scene", c.traffic.pedestrians_per_scene);
    s.get("annotation_range_m", c.traffic.annotation_range_m);
    s.finish();
  }
  if (const json* j = r.child("scenes")) {
    ObjectReader s(*j, "scenes", file);
    s.get("count", c.scenes.count);
    s.get("samples_per_scene", c.scenes.samples_per_scene);
    s.get("ego_speed_mps", c.scenes.ego_speed_mps);
    s.get("first_timestamp_us", c.scenes.first_timestamp_us);
    s.finish();
  }
  if (const json* j = r.child("lidar")) {
    ObjectReader s(*j, "lidar", file);
    s.get("rate_hz", c.lidar.rate_hz);
    s.get("beams", c.lidar.beams);
    s.get("points_per_sweep", c.lidar.points_per_sweep);
    s.get("roof_points", c.lidar.roof_points);
    s.get("max_range_m", c.lidar.max_range_m);
    s.get("range_noise_m", c.lidar.range_noise_m);
    s.get("lidarseg", c.lidar.lidarseg);
    s.finish();
  }
  if (const json* j = r.child("camera")) {
    ObjectReader s(*j, "camera", file);
    s.get("rate_hz", c.camera.rate_hz);
    s.get("channels", c.camera.channels);
    s.get("width_px", c.camera.width_px);
    s.get("height_px", c.camera.height_px);
    s.get("jpeg_quality", c.camera.jpeg_quality);
    s.get("label_noise_rate", c.camera.label_noise_rate);
    s.get("mask_scale_denom", c.camera.mask_scale_denom);
    s.finish();
  }
  if (const json* j = r.child("detections")) {
    ObjectReader s(*j, "detections", file);
    s.get("name", c.detections.name);
    s.get("position_noise_m", c.detections.position_noise_m);
    s.get("yaw_noise_rad", c.detections.yaw_noise_rad);
    s.get("miss_rate", c.detections.miss_rate);
    s.get("false_positives_per_sample", c.detections.false_positives_per_sample);
    s.get("score_true_mean", c.detections.score_true_mean);
    s.get("score_false_mean", c.detections.score_false_mean);
    s.finish();
  }
  r.finish();
  try {
    c.validate();
  } catch (const ConfigError& e) {
    throw ConfigError(file, e.record(), e.expected());
  }
  return c;
}

SynthConfig SynthConfig::from_file(const std::filesystem::path& path) {
  return from_json_text(read_file(path), path.string());
}

std::string SynthConfig::to_json() const {
  json j;
  j["location"] = location;
  j["version"] = version;
  j["map_size_m"] = map_size_m;
  j["seed"] = seed;
  j["city"] = {{"origin_m", city.origin_m},
               {"blocks_x", city.blocks_x},
               {"blocks_y", city.blocks_y},
               {"block_size_m", city.block_size_m},
               {"lane_width_m", city.lane_width_m},
               {"max_lanes_per_direction", city.max_lanes_per_direction},
               {"one_way_fraction", city.one_way_fraction},
               {"parking_fraction", city.parking_fraction},
               {"ring_corner_radius_m", city.ring_corner_radius_m},
               {"sidewalk_width_m", city.sidewalk_width_m},
               {"park_fraction", city.park_fraction},
               {"ground_resolution_m", city.ground_resolution_m}};
  j["traffic"] = {{"moving_vehicles_per_scene", traffic.moving_vehicles_per_scene},
                  {"parked_spacing_m", traffic.parked_spacing_m},
                  {"parked_occupancy", traffic.parked_occupancy},
                  {"pedestrians_per_scene", traffic.pedestrians_per_scene},
                  {"annotation_range_m", traffic.annotation_range_m}};
  j["scenes"] = {{"count", scenes.count},
                 {"samples_per_scene", scenes.samples_per_scene},
                 {"ego_speed_mps", scenes.ego_speed_mps},
                 {"first_timestamp_us", scenes.first_timestamp_us}};
  j["lidar"] = {{"rate_hz", lidar.rate_hz},
                {"beams", lidar.beams},
                {"points_per_sweep", lidar.points_per_sweep},
                {"roof_points", lidar.roof_points},
                {"max_range_m", lidar.max_range_m},
                {"range_noise_m", lidar.range_noise_m},
                {"lidarseg", lidar.lidarseg}};
  j["camera"] = {{"rate_hz", camera.rate_hz},
                 {"channels", camera.channels},
                 {"width_px", camera.width_px},
                 {"height_px", camera.height_px},
                 {"jpeg_quality", camera.jpeg_quality},
                 {"label_noise_rate", camera.label_noise_rate},
                 {"mask_scale_denom", camera.mask_scale_denom}};
  j["detections"] = {{"name", detections.name},
                     {"position_noise_m", detections.position_noise_m},
                     {"yaw_noise_rad", detections.yaw_noise_rad},
                     {"miss_rate", detections.miss_rate},
                     {"false_positives_per_sample", detections.false_positives_per_sample},
                     {"score_true_mean", detections.score_true_mean},
                     {"score_false_mean", detections.score_false_mean}};
  return j.dump(2);
}

}  // namespace nsg::synth
