// The release writer: plans every scene serially (tokens, timestamps, routes), renders all
// sensor frames in parallel with per-frame Rng streams, then writes the tables.
#include "nsg/synth/release.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <ctime>
#include <map>
#include <mutex>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "nsg/synth/camera_sim.h"
#include "nsg/synth/image_encode.h"
#include "nsg/synth/lidar_sim.h"
#include "nsg/synth/traffic.h"
#include "nsg/synth/world.h"
#include "png_stream.h"
#include "py_json.h"

namespace nsg::synth {

using geometry::Pose2;
using geometry::Quaternion;
using geometry::Rigid3;

namespace fs = std::filesystem;

void SynthRunOptions::validate() const {
  NSG_CHECK(!out_dir.empty(), ConfigError, "", "--out", "an output folder");
  NSG_CHECK(threads >= 0 && threads <= 1024, ConfigError, "", "--threads", "a thread count in [0, 1024]");
}

const std::vector<SensorSpec>& sensor_specs() {
  auto yawq = [](double deg) { return geometry::quaternion_from_yaw(deg * 3.141592653589793 / 180.0); };
  // LIDAR_TOP and CAM_FRONT: the n015 calibrations of docs/nuscenes-input.md; the other
  // cameras: calibrations of the same kind (mounting positions/angles of the real rig);
  // radars: approximate mounting positions, facing their directions.
  static const std::vector<SensorSpec> kSpecs = {
      {"CAM_FRONT",
       "camera",
       "725903f5b62f56118f4094b46a4470d8",
       {1.70079118954, 0.0159456324149, 1.51095763913},
       {0.4998015430569128, -0.5030316162024876, 0.4997798114386805, -0.49737083824542755},
       {1266.417203046554, 1266.417203046554, 816.2670197447984, 491.50706579294757}},
      {"CAM_FRONT_RIGHT",
       "camera",
       "2f7ad058f1ac5557bf321c7543758f43",
       {1.5508477543, -0.493404796419, 1.49574800619},
       {0.2060347966337182, -0.2026940577919598, 0.6824507824531167, -0.6713610884174485},
       {1260.8474446004698, 1260.8474446004698, 807.968244525, 495.3344268742088}},
      {"CAM_FRONT_LEFT",
       "camera",
       "ec4b5d41840a509984f7ec36419d4c09",
       {1.52387798135, 0.494631336551, 1.50932822144},
       {0.6757265034669446, -0.6736266522251881, 0.21214015046209478, -0.21122827103904068},
       {1272.5979470598488, 1272.5979470598488, 826.6154927353808, 479.75165386361925}},
      {"CAM_BACK",
       "camera",
       "ce89d4f3050b5892b33b3d328c5e82a3",
       {0.0283260309358, 0.00345136761476, 1.57910346144},
       {0.5037872666382278, -0.49740249788611096, -0.4941850223835201, 0.5045496097725578},
       {809.2209905677063, 809.2209905677063, 829.2196003259838, 481.77842384512485}},
      {"CAM_BACK_LEFT",
       "camera",
       "a89643a5de885c6486df2232dc954da2",
       {1.03569100218, 0.484795032713, 1.59097014818},
       {0.6924185592174665, -0.7031619420114925, -0.11648342771943819, 0.11203317912370753},
       {1256.7414812095406, 1256.7414812095406, 792.1125740759628, 492.7757465151356}},
      {"CAM_BACK_RIGHT",
       "camera",
       "ca7dba2ec9f95951bbe67246f7f2c3f7",
       {1.0148780988, -0.480568219723, 1.56239545128},
       {0.12280980120078765, -0.132400842670559, -0.7004305821388234, 0.690496031265798},
       {1259.5137405846733, 1259.5137405846733, 807.2529053838625, 501.19579884916527}},
      {"LIDAR_TOP",
       "lidar",
       "dc8b396651c05aedbb9cdaae573bb567",
       {0.943713, 0.0, 1.84023},
       {0.7077955119163518, -0.006492242056004365, 0.010646214713995808, -0.7063073142877817},
       {}},
      {"RADAR_FRONT", "radar", "47fcd48f71d75e0da5c8c1704a9bfe0a", {3.412, 0.0, 0.5}, yawq(0.0), {}},
      {"RADAR_FRONT_LEFT", "radar", "1f69f87a4e175e5ba1d03e2e6d9bcd27", {2.422, 0.8, 0.78}, yawq(90.0), {}},
      {"RADAR_FRONT_RIGHT", "radar", "232a6c4dc628532e81de1c57120876e9", {2.422, -0.8, 0.77}, yawq(-90.0), {}},
      {"RADAR_BACK_LEFT", "radar", "df2d5b8be7be55cca33c8c92384f2266", {-0.562, 0.628, 0.53}, yawq(180.0), {}},
      {"RADAR_BACK_RIGHT", "radar", "5c29dee2f70b528a817110173c2e71b9", {-0.562, -0.618, 0.53}, yawq(180.0), {}},
  };
  return kSpecs;
}

std::string semantic_prior_token(const std::string& location) {
  if (location == "singapore-onenorth") return "53992ee3023e5494b90c316c183be829";
  if (location == "singapore-hollandvillage") return "37819e65e09e5547b8a3ceaefba56bb2";
  if (location == "singapore-queenstown") return "93406b464a165eaba6d9de76ca09f5da";
  if (location == "boston-seaport") return "36092f0b03a857c6a3403e25b4b7aab3";
  throw ConfigError("", "location", "one of the four nuScenes locations, got \"" + location + "\"");
}

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kAnnotationPadM = 0.05;

// ---- tokens -----------------------------------------------------------------------------
// Table tokens: 32 hex digits hashed from (seed, kind, indices), so any thread can make any
// token and the result never depends on scheduling.
std::string table_token(uint64_t seed, const char* kind, uint64_t a, uint64_t b = 0, uint64_t c = 0) {
  uint64_t h = mix64(seed ^ hash_string(kind, std::char_traits<char>::length(kind)));
  h = mix64(h ^ a);
  h = mix64(h ^ (b * 0x9e3779b97f4a7c15ULL));
  h = mix64(h ^ (c * 0xc2b2ae3d27d4eb4fULL));
  const uint64_t h2 = mix64(h ^ 0x5bd1e9955bd1e995ULL);
  return strprintf("%016llx%016llx", static_cast<unsigned long long>(h), static_cast<unsigned long long>(h2));
}
// Fixed tokens for the fixed tables (the same in every synthetic release).
std::string fixed_token(const std::string& kind, const std::string& name) {
  const std::string key = kind + ":" + name;
  return table_token(0x6e75'7363'656e'6573ULL, key.c_str(), 0);
}

PyJson vec3(const std::array<double, 3>& v) { return PyJson::array({v[0], v[1], v[2]}); }
PyJson quat(const Quaternion& q) { return PyJson::array({q.w, q.x, q.y, q.z}); }

// ---- fixed tables -------------------------------------------------------------------------
struct CategorySpec {
  const char* name;
  const char* description;
  int index;
};
const std::vector<CategorySpec>& categories() {
  static const std::vector<CategorySpec> k = {
      {"human.pedestrian.adult", "Adult subcategory.", 2},
      {"human.pedestrian.child", "Child subcategory.", 3},
      {"human.pedestrian.wheelchair", "Wheelchairs. If a person is in the wheelchair, include in the annotation.", 8},
      {"human.pedestrian.stroller", "Strollers. If a person is in the stroller, include in the annotation.", 7},
      {"human.pedestrian.personal_mobility",
       "A small electric or self-propelled vehicle, e.g. skateboard, segway, or scooters.", 5},
      {"human.pedestrian.police_officer", "Police officer.", 6},
      {"human.pedestrian.construction_worker", "Construction worker", 4},
      {"animal", "All animals, e.g. cats, rats, dogs, deer, birds.", 1},
      {"vehicle.car",
       "Vehicle designed primarily for personal use, e.g. sedans, hatch-backs, wagons, vans, mini-vans, SUVs and "
       "jeeps.",
       17},
      {"vehicle.motorcycle",
       "Gasoline or electric powered 2-wheeled vehicle designed to move rapidly (at the speed of standard cars) on the "
       "road surface.",
       21},
      {"vehicle.bicycle",
       "Human or electric powered 2-wheeled vehicle designed to travel at lower speeds either on road surface, "
       "sidewalks or bike paths.",
       14},
      {"vehicle.bus.bendy", "Bendy bus subcategory. Annotate each section of the bendy bus individually.", 15},
      {"vehicle.bus.rigid", "Rigid bus subcategory.", 16},
      {"vehicle.truck",
       "Vehicles primarily designed to haul cargo including pick-ups, lorrys, trucks and semi-tractors.", 23},
      {"vehicle.construction",
       "Vehicles primarily designed for construction. Typically very slow moving or stationary.", 18},
      {"vehicle.emergency.ambulance", "All types of ambulances.", 19},
      {"vehicle.emergency.police", "All types of police vehicles including police bicycles and motorcycles.", 20},
      {"vehicle.trailer", "Any vehicle trailer, both for trucks, cars and bikes.", 22},
      {"movable_object.barrier", "Temporary road barrier placed in the scene in order to redirect traffic.", 9},
      {"movable_object.trafficcone", "All types of traffic cone.", 12},
      {"movable_object.pushable_pullable",
       "Objects that a pedestrian may push or pull, e.g. dolleys, wheel barrows, garbage-bins.", 11},
      {"movable_object.debris",
       "Movable object that is left on the driveable surface that is too large to be driven over safely.", 10},
      {"static_object.bicycle_rack", "Area or device intended to park or secure the bicycles in a row.", 13},
      // The classes nuScenes-lidarseg adds (its category.json has all 32, each with index).
      {"noise",
       "Any lidar return that does not correspond to a physical object, such as dust, vapor, noise, fog, raindrops, "
       "smoke and reflections.",
       0},
      {"flat.driveable_surface",
       "All paved or unpaved surfaces that a car can drive on with no concern of traffic rules.", 24},
      {"flat.other",
       "All other forms of horizontal ground-level structures that do not belong to any of driveable_surface, curb, "
       "sidewalk and terrain. Includes elevated parts of traffic islands, delimiters, rail tracks, stairs with at most "
       "3 steps and larger bodies of water - lakes, rivers.",
       25},
      {"flat.sidewalk",
       "Sidewalk, pedestrian walkways, bike paths, etc. Part of the ground designated for pedestrians or cyclists. "
       "Sidewalks do **not** have to be next to a road.",
       26},
      {"flat.terrain",
       "Natural horizontal surfaces such as ground level horizontal vegetation (< 20 cm tall), grass, rolling hills, "
       "soil, sand and gravel.",
       27},
      {"static.manmade",
       "Includes man-made structures but not limited to: buildings, walls, guard rails, fences, poles, drainages, "
       "hydrants, flags, banners, street signs, electric circuit boxes, traffic lights, parking meters and stairs with "
       "more than 3 steps.",
       28},
      {"static.other",
       "Points in the background that are not distinguishable. Or objects that do not match any of the above labels.",
       29},
      {"static.vegetation",
       "Any vegetation in the frame that is higher than the ground, including bushes, plants, potted plants, trees, "
       "etc. Only tall grass (> 20cm) is part of this, ground level grass is part of `flat.terrain`.",
       30},
      {"vehicle.ego",
       "The vehicle on which the cameras, radar and lidar are mounted, that is sometimes visible at the bottom of the "
       "image.",
       31},
  };
  return k;
}
const std::vector<std::pair<const char*, const char*>>& attributes() {
  static const std::vector<std::pair<const char*, const char*>> k = {
      {"vehicle.moving", "Vehicle is moving."},
      {"vehicle.stopped", "Vehicle, with a driver/rider in/on it, is currently stationary but has an intent to move."},
      {"vehicle.parked", "Vehicle is stationary (usually for longer duration) with no immediate intent to move."},
      {"cycle.with_rider", "There is a rider on the bicycle or motorcycle."},
      {"cycle.without_rider", "There is NO rider on the bicycle or motorcycle."},
      {"pedestrian.sitting_lying_down", "The human is sitting or lying down."},
      {"pedestrian.standing", "The human is standing."},
      {"pedestrian.moving", "The human is moving."},
  };
  return k;
}

// ---- scene planning ---------------------------------------------------------------------
const std::vector<std::string>& official_scene_names() {
  static const std::vector<std::string> k = {"scene-0061", "scene-0553", "scene-0655", "scene-0757", "scene-0796",
                                             "scene-1077", "scene-1094", "scene-1100", "scene-0103", "scene-0916"};
  return k;
}
std::string scene_name(int i) {
  if (i < static_cast<int>(official_scene_names().size())) return official_scene_names()[static_cast<size_t>(i)];
  return strprintf("scene-%04d", 2000 + i);  // beyond the official mini names
}

struct Frame {
  std::string token;
  std::string channel;
  int64_t timestamp = 0;
  bool key = false;
  int sample = -1;  // the sample it belongs to (key) or the next sample (non-key)
  std::string filename;
};

struct AnnotationPlan {
  int agent = 0;
  SceneBox box;
  int num_lidar_pts = 0;
  std::string token;
};

struct SampleRec {
  std::string token;
  int64_t timestamp = 0;
  std::vector<AnnotationPlan> anns;
};

struct SceneRun {
  int index = 0;
  std::string token, log_token, logfile, date;
  int64_t t0 = 0;
  ScenePlan plan;
  std::vector<SampleRec> samples;
  std::map<std::string, std::vector<Frame>> frames;  // per channel, in time order
  std::map<std::string, std::string> calib_tokens;
};

double seconds_since(const SceneRun& s, int64_t ts) { return static_cast<double>(ts - s.t0) * 1e-6; }

Rigid3 ego_transform(const Pose2& p) {
  return Rigid3::from_pose({p.x, p.y, 0.0}, geometry::quaternion_from_yaw(p.yaw));
}
Rigid3 sensor_transform(const SensorSpec& s) { return Rigid3::from_pose(s.translation, s.rotation); }

const SensorSpec& spec(const std::string& channel) {
  for (const SensorSpec& s : sensor_specs())
    if (s.channel == channel) return s;
  throw InternalError("", channel, "unknown channel");
}

std::string log_name(const SynthConfig& cfg, int64_t t0_us, std::string* date) {
  const bool boston = cfg.location == "boston-seaport";
  const int tz_hours = boston ? -4 : 8;
  const std::time_t t = static_cast<std::time_t>(t0_us / 1000000 + tz_hours * 3600);
  std::tm tm{};
  gmtime_r(&t, &tm);
  *date = strprintf("%04d-%02d-%02d", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday);
  return strprintf("%s-%04d-%02d-%02d-%02d-%02d-%02d%s", boston ? "n008" : "n015", tm.tm_year + 1900, tm.tm_mon + 1,
                   tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, boston ? "-0400" : "+0800");
}

// Plans timestamps, frames and annotated agents of one scene (serial, deterministic).
SceneRun plan_scene_run(const World& world, int index, uint64_t seed) {
  const SynthConfig& cfg = world.config;
  SceneRun s;
  s.index = index;
  Rng rng(seed, 0x1000 + static_cast<uint64_t>(index));
  const int n_samples = cfg.scenes.samples_per_scene;
  const double duration_s = (n_samples - 1) * 0.5;
  s.t0 = cfg.scenes.first_timestamp_us + static_cast<int64_t>(index) * static_cast<int64_t>((duration_s + 60.0) * 1e6);
  s.token = table_token(seed, "scene", static_cast<uint64_t>(index));
  s.log_token = table_token(seed, "log", static_cast<uint64_t>(index));
  s.logfile = log_name(cfg, s.t0, &s.date);
  s.plan = plan_scene(world, duration_s + 0.5, rng);
  for (const SensorSpec& sp : sensor_specs())
    s.calib_tokens[sp.channel] = table_token(seed, "calibrated_sensor", static_cast<uint64_t>(index),
                                             hash_string(sp.channel.data(), sp.channel.size()));

  // LiDAR: 20 Hz sweeps with ±300 µs jitter; every (rate/2)-th sweep is a key frame.
  const int per_key = static_cast<int>(std::lround(cfg.lidar.rate_hz / 2.0));
  const double lidar_period_us = 1e6 / cfg.lidar.rate_hz;
  std::vector<Frame>& lidar = s.frames["LIDAR_TOP"];
  const int n_sweeps = (n_samples - 1) * per_key + 1;
  for (int k = 0; k < n_sweeps; ++k) {
    Frame f;
    f.channel = "LIDAR_TOP";
    f.timestamp =
        s.t0 + std::llround(k * lidar_period_us) + (k == 0 ? 0 : rng.uniform_int(int64_t{-300}, int64_t{300}));
    f.key = k % per_key == 0;
    f.sample = (k + per_key - 1) / per_key;  // key: its own sample; non-key: the next one
    lidar.push_back(f);
  }
  for (int i = 0; i < n_samples; ++i) {
    SampleRec rec;
    rec.token = table_token(seed, "sample", static_cast<uint64_t>(index), static_cast<uint64_t>(i));
    rec.timestamp = lidar[static_cast<size_t>(i * per_key)].timestamp;
    s.samples.push_back(rec);
  }
  // Cameras: free-running at their rate, phase-shifted by where the LiDAR beam passes each
  // camera (clockwise spin from the front); the key frame of a sample is the closest in time.
  const double cam_period_us = 1e6 / cfg.camera.rate_hz;
  const std::map<std::string, double> yaw_deg = {{"CAM_FRONT", 0.0},         {"CAM_FRONT_RIGHT", -55.0},
                                                 {"CAM_BACK_RIGHT", -110.0}, {"CAM_BACK", 180.0},
                                                 {"CAM_BACK_LEFT", 110.0},   {"CAM_FRONT_LEFT", 55.0}};
  for (const std::string& ch : cfg.camera.channels) {
    const double cw = std::fmod(360.0 - yaw_deg.at(ch), 360.0);
    const int64_t phase = std::llround(cw / 360.0 * 50000.0);  // the real LiDAR spins at 20 Hz
    std::vector<Frame> all;
    for (int j = 0;; ++j) {
      const int64_t ts = s.t0 - std::llround(cam_period_us) + phase + std::llround(j * cam_period_us) +
                         rng.uniform_int(int64_t{-200}, int64_t{200});
      if (ts > s.samples.back().timestamp + std::llround(cam_period_us)) break;
      Frame f;
      f.channel = ch;
      f.timestamp = ts;
      all.push_back(f);
    }
    std::vector<size_t> key_idx;
    for (const SampleRec& smp : s.samples) {
      size_t best = 0;
      for (size_t j = 1; j < all.size(); ++j)
        if (std::llabs(all[j].timestamp - smp.timestamp) < std::llabs(all[best].timestamp - smp.timestamp)) best = j;
      if (!key_idx.empty() && best <= key_idx.back())
        throw InternalError("", ch, "two samples share a key camera frame (camera rate below 2 Hz?)");
      key_idx.push_back(best);
    }
    std::vector<Frame>& out = s.frames[ch];
    size_t next_key = 0;
    for (size_t j = key_idx.front(); j <= key_idx.back(); ++j) {
      Frame f = all[j];
      f.key = j == key_idx[next_key];
      f.sample = static_cast<int>(next_key);
      if (f.key) ++next_key;
      out.push_back(f);
    }
  }
  for (auto& [ch, frames] : s.frames) {
    const SensorSpec& sp = spec(ch);
    const std::string ext = sp.modality == "lidar" ? "pcd.bin" : "jpg";
    for (size_t j = 0; j < frames.size(); ++j) {
      Frame& f = frames[j];
      f.token = table_token(seed, "sample_data", static_cast<uint64_t>(index), hash_string(ch.data(), ch.size()),
                            static_cast<uint64_t>(j));
      f.filename = std::string(f.key ? "samples/" : "sweeps/") + ch + "/" + s.logfile + "__" + ch + "__" +
                   std::to_string(f.timestamp) + "." + ext;
    }
  }
  // Annotated agents: within range of the ego at each sample.
  for (size_t i = 0; i < s.samples.size(); ++i) {
    const double t = seconds_since(s, s.samples[i].timestamp);
    const Pose2 ego = s.plan.ego_pose_at(t);
    for (size_t a = 0; a < s.plan.agents.size(); ++a) {
      SceneBox box = s.plan.agents[a].box_at(t);
      if (std::hypot(box.center_m.x() - ego.x, box.center_m.y() - ego.y) > cfg.traffic.annotation_range_m) continue;
      // Annotators draw boxes slightly larger than the object: 5 cm on every side keeps the
      // returns from its faces (with range noise) inside the box.
      box.length_m += 2.0 * kAnnotationPadM;
      box.width_m += 2.0 * kAnnotationPadM;
      box.height_m += 2.0 * kAnnotationPadM;
      AnnotationPlan ap;
      ap.agent = static_cast<int>(a);
      ap.box = box;
      ap.token = table_token(seed, "sample_annotation", static_cast<uint64_t>(index), i, a);
      s.samples[i].anns.push_back(ap);
    }
  }
  return s;
}

std::vector<SceneBox> boxes_at(const ScenePlan& plan, double t) {
  std::vector<SceneBox> out;
  out.reserve(plan.agents.size());
  for (const Agent& a : plan.agents) out.push_back(a.box_at(t));
  return out;
}

// Points of a sweep (sensor frame) inside a box, after the devkit's sensor → global chain.
int count_points_in_box(const std::vector<float>& global_xyz5, const SceneBox& b) {
  const double c = std::cos(b.yaw_rad), s = std::sin(b.yaw_rad);
  int n = 0;
  for (size_t i = 0; i + 4 < global_xyz5.size(); i += 5) {
    const double dx = global_xyz5[i] - b.center_m.x(), dy = global_xyz5[i + 1] - b.center_m.y();
    const double dz = global_xyz5[i + 2] - b.center_m.z();
    const double lx = c * dx + s * dy, ly = -s * dx + c * dy;
    if (std::fabs(lx) <= b.length_m / 2.0 && std::fabs(ly) <= b.width_m / 2.0 && std::fabs(dz) <= b.height_m / 2.0) ++n;
  }
  return n;
}

Eigen::Matrix3d intrinsic_for(const SensorSpec& sp, const CameraConfig& cam) {
  const double sx = cam.width_px / 1600.0, sy = cam.height_px / 900.0;
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = sp.intrinsic[0] * sx;
  k(1, 1) = sp.intrinsic[1] * sy;
  k(0, 2) = sp.intrinsic[2] * sx;
  k(1, 2) = sp.intrinsic[3] * sy;
  return k;
}

class ReleaseWriter {
 public:
  ReleaseWriter(const SynthConfig& cfg, const SynthRunOptions& opt) : cfg_(cfg), opt_(opt), seed_(cfg.seed) {}

  SynthSummary run() {
    log::info("synth: building the world (" + cfg_.location + ")");
    world_ = build_world(cfg_, seed_);
    for (const LaneInfo& l : world_.lanes) (l.is_connector ? summary_.lane_connectors : summary_.lanes)++;
    write_maps();
    for (int i = 0; i < cfg_.scenes.count; ++i) scenes_.push_back(plan_scene_run(world_, i, seed_));
    render_frames();
    write_tables();
    write_detections();
    summary_.scenes = static_cast<int>(scenes_.size());
    summary_.files = files_.load();
    summary_.bytes = bytes_.load();
    return summary_;
  }

 private:
  void put(const std::string& rel, std::string_view data) {
    write_file_atomic(opt_.out_dir / rel, data);
    files_ += 1;
    bytes_ += data.size();
  }
  void put(const std::string& rel, const std::vector<uint8_t>& data) {
    put(rel, std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
  }
  void count_file(const fs::path& p) {
    files_ += 1;
    bytes_ += fs::file_size(p);
  }

  // ---- maps -------------------------------------------------------------------------------
  void write_maps() {
    put("maps/expansion/" + cfg_.location + ".json", world_.map_json);
    const GroundRaster& g = *world_.ground;
    const double w_m = cfg_.map_size_m[0], h_m = cfg_.map_size_m[1];
    // Semantic prior: 10 px/m, pixel (c, r) samples x = c/10, y = H − r/10 (devkit MapMask).
    const int w = static_cast<int>(std::ceil(w_m * 10.0)), h = static_cast<int>(std::ceil(h_m * 10.0));
    const fs::path prior = opt_.out_dir / "maps" / (semantic_prior_token(cfg_.location) + ".png");
    write_gray_png_rows(prior, w, h, [&](int row, uint8_t* buf) {
      const double y = h_m - row * 0.1;
      for (int c = 0; c < w; ++c) buf[c] = is_drivable_material(g.material(c * 0.1, y)) ? 255 : 0;
    });
    count_file(prior);
    // Basemap: a gray LiDAR-like picture of the ground at 2 px/m over the canvas.
    const int bw = static_cast<int>(std::ceil(w_m * 2.0)), bh = static_cast<int>(std::ceil(h_m * 2.0));
    const fs::path base = opt_.out_dir / "maps" / "basemap" / (cfg_.location + ".png");
    write_gray_png_rows(base, bw, bh, [&](int row, uint8_t* buf) {
      const double y = h_m - (row + 0.5) * 0.5;
      for (int c = 0; c < bw; ++c) {
        const GroundMaterial m = g.material((c + 0.5) * 0.5, y);
        buf[c] = static_cast<uint8_t>(std::clamp(lidar_ground_intensity(m) * 2.0 + 20.0, 0.0, 255.0));
      }
    });
    count_file(base);
  }

  // ---- frames -----------------------------------------------------------------------------
  struct Task {
    int scene;
    const Frame* frame;
  };

  void render_frames() {
    std::vector<Task> tasks;
    for (const SceneRun& s : scenes_)
      for (const auto& [ch, frames] : s.frames)
        for (const Frame& f : frames) tasks.push_back({s.index, &f});
    Progress progress("synth frames", tasks.size(), opt_.progress);
    parallel_for(tasks.size(), opt_.threads, [&](size_t i) {
      render_task(tasks[i], i);
      progress.advance();
      progress.set_detail(human_bytes(static_cast<double>(bytes_.load())) + " written");
    });
    progress.finish();
  }

  void render_task(const Task& task, size_t task_index) {
    SceneRun& s = scenes_[static_cast<size_t>(task.scene)];
    const Frame& f = *task.frame;
    const double t = seconds_since(s, f.timestamp);
    const SensorSpec& sp = spec(f.channel);
    Rng rng(seed_, mix64(0x6672616d65ULL ^ (static_cast<uint64_t>(task.scene) << 40) ^
                         hash_string(f.token.data(), f.token.size())));
    (void)task_index;
    const SceneSnapshot snap = world_.snapshot(boxes_at(s.plan, t));
    const Rigid3 global_from_sensor = ego_transform(s.plan.ego_pose_at(t)) * sensor_transform(sp);
    if (sp.modality == "lidar") {
      LidarSimOptions lo;
      lo.beams = cfg_.lidar.beams;
      lo.points_per_sweep = cfg_.lidar.points_per_sweep;
      lo.roof_points = cfg_.lidar.roof_points;
      lo.max_range_m = cfg_.lidar.max_range_m;
      lo.range_noise_m = cfg_.lidar.range_noise_m;
      const SceneRaycaster caster(snap, lo.raycast);
      std::vector<uint8_t> labels;
      const bool lidarseg = f.key && cfg_.lidar.lidarseg;
      std::vector<float> pts = simulate_lidar_sweep(caster, global_from_sensor, lo, rng, lidarseg ? &labels : nullptr);
      put(f.filename, std::string_view(reinterpret_cast<const char*>(pts.data()), pts.size() * sizeof(float)));
      if (lidarseg) put(lidarseg_filename(f), labels);
      if (f.key) {
        // num_lidar_pts: the sweep in the global frame with the devkit chain.
        const Pose2 ego = s.plan.ego_pose_at(t);
        geometry::transform_points_devkit(sensor_transform(sp), pts.data(), pts.size() / 5, 5);
        geometry::transform_points_devkit(ego_transform(ego), pts.data(), pts.size() / 5, 5);
        for (AnnotationPlan& ap : s.samples[static_cast<size_t>(f.sample)].anns)
          ap.num_lidar_pts = count_points_in_box(pts, ap.box);
      }
    } else {
      CameraSimOptions co;
      co.width_px = cfg_.camera.width_px;
      co.height_px = cfg_.camera.height_px;
      co.label_noise_rate = cfg_.camera.label_noise_rate;
      const SceneRaycaster caster(snap, co.raycast);
      const CameraImage img = render_camera(caster, global_from_sensor, intrinsic_for(sp, cfg_.camera), co, rng);
      put(f.filename, encode_jpeg(img, cfg_.camera.jpeg_quality));
      const std::string base = fs::path(f.filename).filename().replace_extension("").string();
      put("semantic/" + f.channel + "/" + base + ".png", encode_mask(img, cfg_.camera.mask_scale_denom));
    }
  }

  // The class mask at 1/n of the image's size: pixel k is the class at full pixel k·n.
  static std::vector<uint8_t> encode_mask(const CameraImage& img, int n) {
    if (n == 1) return encode_png_gray8_from(img);
    const int w = (img.width_px + n - 1) / n, h = (img.height_px + n - 1) / n;
    std::vector<uint8_t> small(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        small[static_cast<size_t>(y) * w + x] = img.classes[static_cast<size_t>(y) * n * img.width_px + x * n];
    return encode_png_gray8(small.data(), w, h);
  }

  // ---- tables -----------------------------------------------------------------------------
  // nuScenes-lidarseg's layout: lidarseg/<version>/<sample_data token>_lidarseg.bin.
  std::string lidarseg_filename(const Frame& f) const {
    return "lidarseg/" + cfg_.version + "/" + f.token + "_lidarseg.bin";
  }

  // lidarseg.json: one record per key-frame LIDAR_TOP sweep, its token the sweep's
  // sample_data token (the devkit looks records up by it), in sample_data order.
  void write_lidarseg_table() {
    PyJson lidarseg = PyJson::array();
    for (const SceneRun& s : scenes_) {
      auto it = s.frames.find("LIDAR_TOP");
      if (it == s.frames.end()) continue;
      for (const Frame& f : it->second) {
        if (!f.key) continue;
        lidarseg.push_back(
            PyJson{{"token", f.token}, {"sample_data_token", f.token}, {"filename", lidarseg_filename(f)}});
      }
    }
    write_table("lidarseg", lidarseg);
  }

  void write_table(const std::string& name, const PyJson& records) {
    put(cfg_.version + "/" + name + ".json", py_json_dump(records, PyJsonStyle::kIndent0));
  }

  static std::string visibility_of(int pts) {
    if (pts == 0) return "1";
    if (pts < 5) return "2";
    if (pts < 20) return "3";
    return "4";
  }

  std::string attribute_of(const Agent& a, double t) const {
    if (a.kind == Agent::Kind::kParked) return "vehicle.parked";
    if (a.kind == Agent::Kind::kPedestrian) return "pedestrian.moving";
    return a.moving_at(t) ? "vehicle.moving" : "vehicle.stopped";
  }

  void write_tables() {
    PyJson sensor = PyJson::array(), category = PyJson::array(), attribute = PyJson::array(),
           visibility = PyJson::array();
    for (const SensorSpec& sp : sensor_specs())
      sensor.push_back(PyJson{{"token", sp.token}, {"channel", sp.channel}, {"modality", sp.modality}});
    for (const CategorySpec& c : categories())
      category.push_back(PyJson{{"token", fixed_token("category", c.name)},
                                {"name", c.name},
                                {"description", c.description},
                                {"index", c.index}});
    for (const auto& [name, desc] : attributes())
      attribute.push_back(PyJson{{"token", fixed_token("attribute", name)}, {"name", name}, {"description", desc}});
    const char* levels[] = {"v0-40", "v40-60", "v60-80", "v80-100"};
    const char* vis_desc[] = {
        "visibility of whole object is between 0 and 40%", "visibility of whole object is between 40 and 60%",
        "visibility of whole object is between 60 and 80%", "visibility of whole object is between 80 and 100%"};
    for (int i = 0; i < 4; ++i)
      visibility.push_back(
          PyJson{{"description", vis_desc[i]}, {"token", std::to_string(i + 1)}, {"level", levels[i]}});

    PyJson scene = PyJson::array(), sample = PyJson::array(), sample_data = PyJson::array(), ego_pose = PyJson::array(),
           calibrated = PyJson::array(), log = PyJson::array(), sample_ann = PyJson::array(),
           instance = PyJson::array();
    std::vector<std::string> log_tokens;
    for (const SceneRun& s : scenes_) {
      log.push_back(PyJson{{"token", s.log_token},
                           {"logfile", s.logfile},
                           {"vehicle", s.logfile.substr(0, 4)},
                           {"date_captured", s.date},
                           {"location", cfg_.location}});
      log_tokens.push_back(s.log_token);
      scene.push_back(PyJson{
          {"token", s.token},
          {"log_token", s.log_token},
          {"nbr_samples", static_cast<int>(s.samples.size())},
          {"first_sample_token", s.samples.front().token},
          {"last_sample_token", s.samples.back().token},
          {"name", scene_name(s.index)},
          {"description",
           "synthetic city drive, " + std::string(cfg_.right_hand_traffic() ? "right" : "left") + "-hand traffic"}});
      for (size_t i = 0; i < s.samples.size(); ++i) {
        sample.push_back(PyJson{{"token", s.samples[i].token},
                                {"timestamp", s.samples[i].timestamp},
                                {"prev", i == 0 ? "" : s.samples[i - 1].token},
                                {"next", i + 1 == s.samples.size() ? "" : s.samples[i + 1].token},
                                {"scene_token", s.token}});
      }
      for (const SensorSpec& sp : sensor_specs()) {
        PyJson k = PyJson::array();
        if (sp.modality == "camera") {
          const Eigen::Matrix3d m = intrinsic_for(sp, cfg_.camera);
          for (int r = 0; r < 3; ++r) k.push_back(PyJson::array({m(r, 0), m(r, 1), m(r, 2)}));
        }
        calibrated.push_back(PyJson{{"token", s.calib_tokens.at(sp.channel)},
                                    {"sensor_token", sp.token},
                                    {"translation", vec3(sp.translation)},
                                    {"rotation", quat(sp.rotation)},
                                    {"camera_intrinsic", k}});
      }
      for (const SensorSpec& sp : sensor_specs()) {
        auto it = s.frames.find(sp.channel);
        if (it == s.frames.end()) continue;
        const std::vector<Frame>& frames = it->second;
        for (size_t j = 0; j < frames.size(); ++j) {
          const Frame& f = frames[j];
          const bool cam = sp.modality == "camera";
          sample_data.push_back(PyJson{{"token", f.token},
                                       {"sample_token", s.samples[static_cast<size_t>(f.sample)].token},
                                       {"ego_pose_token", f.token},
                                       {"calibrated_sensor_token", s.calib_tokens.at(sp.channel)},
                                       {"timestamp", f.timestamp},
                                       {"fileformat", cam ? "jpg" : "pcd"},
                                       {"is_key_frame", f.key},
                                       {"height", cam ? cfg_.camera.height_px : 0},
                                       {"width", cam ? cfg_.camera.width_px : 0},
                                       {"filename", f.filename},
                                       {"prev", j == 0 ? "" : frames[j - 1].token},
                                       {"next", j + 1 == frames.size() ? "" : frames[j + 1].token}});
          const Pose2 p = s.plan.ego_pose_at(seconds_since(s, f.timestamp));
          ego_pose.push_back(PyJson{{"token", f.token},
                                    {"timestamp", f.timestamp},
                                    {"rotation", quat(geometry::quaternion_from_yaw(p.yaw))},
                                    {"translation", PyJson::array({p.x, p.y, 0.0})}});
          ++summary_.sample_data;
        }
      }
      // Instances: one per agent with annotations in this scene; annotations chained.
      std::map<int, std::vector<std::pair<size_t, const AnnotationPlan*>>> by_agent;
      for (size_t i = 0; i < s.samples.size(); ++i)
        for (const AnnotationPlan& ap : s.samples[i].anns) by_agent[ap.agent].push_back({i, &ap});
      for (const auto& [agent_idx, anns] : by_agent) {
        const Agent& agent = s.plan.agents[static_cast<size_t>(agent_idx)];
        const std::string inst =
            table_token(seed_, "instance", static_cast<uint64_t>(s.index), static_cast<uint64_t>(agent_idx));
        instance.push_back(PyJson{{"token", inst},
                                  {"category_token", fixed_token("category", agent.category)},
                                  {"nbr_annotations", static_cast<int>(anns.size())},
                                  {"first_annotation_token", anns.front().second->token},
                                  {"last_annotation_token", anns.back().second->token}});
        for (size_t k = 0; k < anns.size(); ++k) {
          const auto& [si, ap] = anns[k];
          const SceneBox& b = ap->box;
          const double t = seconds_since(s, s.samples[si].timestamp);
          sample_ann.push_back(
              PyJson{{"token", ap->token},
                     {"sample_token", s.samples[si].token},
                     {"instance_token", inst},
                     {"visibility_token", visibility_of(ap->num_lidar_pts)},
                     {"attribute_tokens", PyJson::array({fixed_token("attribute", attribute_of(agent, t))})},
                     {"translation", PyJson::array({b.center_m.x(), b.center_m.y(), b.center_m.z()})},
                     {"size", PyJson::array({b.width_m, b.length_m, b.height_m})},
                     {"rotation", quat(geometry::quaternion_from_yaw(b.yaw_rad))},
                     {"prev", k == 0 ? "" : anns[k - 1].second->token},
                     {"next", k + 1 == anns.size() ? "" : anns[k + 1].second->token},
                     {"num_lidar_pts", ap->num_lidar_pts},
                     {"num_radar_pts", 0}});
          ++summary_.annotations;
        }
        ++summary_.instances;
      }
      summary_.samples += static_cast<int>(s.samples.size());
    }
    PyJson map = PyJson::array();
    const std::string map_token = semantic_prior_token(cfg_.location);
    map.push_back(PyJson{{"category", "semantic_prior"},
                         {"token", map_token},
                         {"filename", "maps/" + map_token + ".png"},
                         {"log_tokens", log_tokens}});
    write_table("attribute", attribute);
    write_table("calibrated_sensor", calibrated);
    write_table("category", category);
    write_table("ego_pose", ego_pose);
    write_table("instance", instance);
    write_table("log", log);
    write_table("map", map);
    write_table("sample", sample);
    write_table("sample_annotation", sample_ann);
    write_table("sample_data", sample_data);
    write_table("scene", scene);
    write_table("sensor", sensor);
    write_table("visibility", visibility);
    if (cfg_.lidar.lidarseg) write_lidarseg_table();
  }

  // ---- detections -------------------------------------------------------------------------
  static const char* detection_name(const std::string& category) {
    if (category == "vehicle.car") return "car";
    if (category == "vehicle.truck") return "truck";
    if (category == "vehicle.bus.rigid" || category == "vehicle.bus.bendy") return "bus";
    if (category.rfind("human.pedestrian.", 0) == 0) return "pedestrian";
    return nullptr;
  }

  PyJson detection_box(const std::string& sample_token, const SceneBox& b, const std::array<double, 2>& velocity,
                       const std::string& name, double score, const std::string& attr) {
    return PyJson{{"sample_token", sample_token},
                  {"translation", PyJson::array({b.center_m.x(), b.center_m.y(), b.center_m.z()})},
                  {"size", PyJson::array({b.width_m, b.length_m, b.height_m})},
                  {"rotation", quat(geometry::quaternion_from_yaw(b.yaw_rad))},
                  {"velocity", PyJson::array({velocity[0], velocity[1]})},
                  {"detection_name", name},
                  {"detection_score", score},
                  {"attribute_name", attr}};
  }

  void write_detections() {
    const DetectionsConfig& dc = cfg_.detections;
    PyJson results = PyJson::object();
    for (const SceneRun& s : scenes_) {
      for (size_t i = 0; i < s.samples.size(); ++i) {
        const SampleRec& smp = s.samples[i];
        Rng rng(seed_, mix64(0x646574ULL ^ hash_string(smp.token.data(), smp.token.size())));
        const double t = seconds_since(s, smp.timestamp);
        PyJson boxes = PyJson::array();
        for (const AnnotationPlan& ap : smp.anns) {
          const Agent& agent = s.plan.agents[static_cast<size_t>(ap.agent)];
          const char* name = detection_name(agent.category);
          if (!name || rng.bernoulli(dc.miss_rate)) continue;
          SceneBox b = ap.box;
          b.center_m.x() += rng.normal(0.0, dc.position_noise_m);
          b.center_m.y() += rng.normal(0.0, dc.position_noise_m);
          b.yaw_rad = geometry::wrap_angle_devkit(b.yaw_rad + rng.normal(0.0, dc.yaw_noise_rad));
          const double speed = agent.moving_at(t) && agent.kind == Agent::Kind::kMoving ? agent.speed_mps : 0.0;
          const double yaw = ap.box.yaw_rad;
          const double score = std::clamp(rng.normal(dc.score_true_mean, 0.1), 0.01, 1.0);
          boxes.push_back(detection_box(smp.token, b, {speed * std::cos(yaw), speed * std::sin(yaw)}, name, score,
                                        attribute_of(agent, t)));
        }
        // False positives: cars scattered around the ego.
        const Pose2 ego = s.plan.ego_pose_at(t);
        int n_fp = static_cast<int>(dc.false_positives_per_sample);
        if (rng.bernoulli(dc.false_positives_per_sample - n_fp)) ++n_fp;
        for (int k = 0; k < n_fp; ++k) {
          SceneBox b;
          const double r = rng.uniform(5.0, 45.0), a = rng.uniform(-kPi, kPi);
          b.center_m = {ego.x + r * std::cos(a), ego.y + r * std::sin(a), 0.8};
          b.yaw_rad = rng.uniform(-kPi, kPi);
          b.length_m = 4.5;
          b.width_m = 1.9;
          b.height_m = 1.6;
          const double score = std::clamp(rng.normal(dc.score_false_mean, 0.1), 0.01, 1.0);
          boxes.push_back(detection_box(smp.token, b, {0.0, 0.0}, "car", score, "vehicle.parked"));
        }
        results[smp.token] = boxes;
      }
    }
    PyJson root{{"meta", PyJson{{"use_camera", false},
                                {"use_lidar", true},
                                {"use_radar", false},
                                {"use_map", false},
                                {"use_external", false}}},
                {"results", results}};
    put("detections/" + dc.name + ".json", py_json_dump(root, PyJsonStyle::kCompact));
  }

  const SynthConfig& cfg_;
  const SynthRunOptions& opt_;
  uint64_t seed_;
  World world_;
  std::vector<SceneRun> scenes_;
  SynthSummary summary_;
  std::atomic<uint64_t> files_{0};
  std::atomic<uint64_t> bytes_{0};
};

}  // namespace

SynthSummary write_release(const SynthConfig& config, const SynthRunOptions& options) {
  config.validate();
  options.validate();
  ReleaseWriter writer(config, options);
  return writer.run();
}

}  // namespace nsg::synth
