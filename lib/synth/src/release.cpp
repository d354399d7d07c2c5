// The release writer: plans every scene serially (tokens, timestamps, routes), renders all
// sensor frames in parallel with per-frame Rng streams, then writes the tables.
// This file: the sensor rig, the tokens, the run order, file output and the maps; the scene
// plans, sensor files and tables are in release_plan.cpp, release_frames.cpp and
// release_tables.cpp (release_writer.h).
#include "nsg/synth/release.h"

#include <algorithm>
#include <cmath>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "nsg/synth/lidar_sim.h"
#include "nsg/synth/world.h"
#include "png_stream.h"
#include "release_writer.h"

namespace nsg::synth {

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

namespace release_detail {

// ---- tokens -----------------------------------------------------------------------------
// Table tokens: 32 hex digits hashed from (seed, kind, indices), so any thread can make any
// token and the result never depends on scheduling.
std::string table_token(uint64_t seed, const char* kind, uint64_t a, uint64_t b, uint64_t c) {
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

const SensorSpec& spec(const std::string& channel) {
  for (const SensorSpec& s : sensor_specs())
    if (s.channel == channel) return s;
  throw InternalError("", channel, "unknown channel");
}

SynthSummary ReleaseWriter::run() {
  log::info("synth: building the world (" + cfg_.location + ")");
  if (cfg_.changes.any()) {
    ChangedWorld worlds = build_changed_world(cfg_, seed_);
    world_ = std::move(worlds.prior);
    current_ = std::move(worlds.current);
    edits_ = std::move(worlds.edits);
    changes_date_ = changes_date(cfg_);
    log::info(strprintf("synth: %zu map changes from %s on", edits_.size(), changes_date_.c_str()));
  } else {
    world_ = build_world(cfg_, seed_);
  }
  // The counts of the map the release's maps/expansion/ holds (the latest).
  for (const LaneInfo& l : (cfg_.changes.any() ? current_ : world_).lanes)
    (l.is_connector ? summary_.lane_connectors : summary_.lanes)++;
  write_maps();
  for (int i = 0; i < cfg_.scenes.count; ++i) {
    const bool changed = cfg_.changes.any() && scene_date(cfg_, i) >= changes_date_;
    scenes_.push_back(plan_scene_run(changed ? current_ : world_, i, seed_));
    scenes_.back().changed_world = changed;
  }
  render_frames();
  write_tables();
  write_detections();
  summary_.scenes = static_cast<int>(scenes_.size());
  summary_.files = files_.load();
  summary_.bytes = bytes_.load();
  return summary_;
}

void ReleaseWriter::put(const std::string& rel, std::string_view data) {
  write_file_atomic(opt_.out_dir / rel, data);
  files_ += 1;
  bytes_ += data.size();
}
void ReleaseWriter::put(const std::string& rel, const std::vector<uint8_t>& data) {
  put(rel, std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
}
void ReleaseWriter::count_file(const fs::path& p) {
  files_ += 1;
  bytes_ += fs::file_size(p);
}

// ---- maps -------------------------------------------------------------------------------

// changes.json: the map changes of a release made with config `changes` (changes.h).
std::string ReleaseWriter::changes_json() const {
  MapChanges c;
  c.location = cfg_.location;
  c.from_day = cfg_.changes.from_day;
  c.date = changes_date_;
  c.edits = edits_;
  return map_changes_text(c);
}

void ReleaseWriter::write_maps() {
  // maps/expansion/ holds the latest map, as a map release published after the changes does;
  // the map before them goes to maps/prior/expansion/.
  const World& latest = cfg_.changes.any() ? current_ : world_;
  put("maps/expansion/" + cfg_.location + ".json", latest.map_json);
  if (cfg_.changes.any()) {
    put("maps/prior/expansion/" + cfg_.location + ".json", world_.map_json);
    put("changes.json", changes_json());
  }
  const GroundRaster& g = *latest.ground;
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

}  // namespace release_detail

SynthSummary write_release(const SynthConfig& config, const SynthRunOptions& options) {
  config.validate();
  options.validate();
  release_detail::ReleaseWriter writer(config, options);
  return writer.run();
}

}  // namespace nsg::synth
