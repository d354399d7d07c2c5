#pragma once
// The release writer's shared state, internal to the synth module: the planned scenes and
// frames and the ReleaseWriter class whose members are split by what they write —
// release.cpp: the run order, tokens, file output and the maps;
// release_plan.cpp: the serial, deterministic plan of each scene (timestamps, frames, agents);
// release_frames.cpp: the sensor files (LiDAR sweeps, lidarseg labels, camera images, masks);
// release_tables.cpp: the JSON tables, lidarseg.json and the detections file.
#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "nsg/synth/camera_sim.h"
#include "nsg/synth/config.h"
#include "nsg/synth/release.h"
#include "nsg/synth/traffic.h"
#include "nsg/synth/changes.h"
#include "nsg/synth/world.h"
#include "py_json.h"

namespace nsg::synth::release_detail {

namespace fs = std::filesystem;

// Table tokens: 32 hex digits hashed from (seed, kind, indices), so any thread can make any
// token and the result never depends on scheduling.
std::string table_token(uint64_t seed, const char* kind, uint64_t a, uint64_t b = 0, uint64_t c = 0);
// Fixed tokens for the fixed tables (the same in every synthetic release).
std::string fixed_token(const std::string& kind, const std::string& name);

// ---- scene planning ---------------------------------------------------------------------
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
  bool changed_world = false;  // captured on or after the map changes' date (config changes)
};

inline double seconds_since(const SceneRun& s, int64_t ts) { return static_cast<double>(ts - s.t0) * 1e-6; }

// The sensor of a channel; InternalError for an unknown one.
const SensorSpec& spec(const std::string& channel);

// The camera intrinsics of `sp` scaled from 1600×900 to the configured image size.
Eigen::Matrix3d intrinsic_for(const SensorSpec& sp, const CameraConfig& cam);

// Plans timestamps, frames and annotated agents of one scene (serial, deterministic).
SceneRun plan_scene_run(const World& world, int index, uint64_t seed);

// The capture day of scene `index` (floor(index · capture_days / count)) and its log's
// date_captured, YYYY-MM-DD, as plan_scene_run gives them.
int64_t capture_day(const SynthConfig& cfg, int index);
std::string scene_date(const SynthConfig& cfg, int index);
// The date from which the world is changed (config changes): the date of the first scene
// captured on changes.from_day or later (of that day's start when no scene is). A scene is
// rendered in the changed world when its date is this or later, so a split by date
// (generate's before-after preset) splits the release where the world changed.
std::string changes_date(const SynthConfig& cfg);

struct ReleaseTables;  // release_tables.cpp

// Writes one release: build_world, the maps, the scene plans, the sensor files, the tables and
// the detections, in that order. run() once.
class ReleaseWriter {
 public:
  ReleaseWriter(const SynthConfig& cfg, const SynthRunOptions& opt) : cfg_(cfg), opt_(opt), seed_(cfg.seed) {}

  SynthSummary run();

 private:
  void put(const std::string& rel, std::string_view data);
  void put(const std::string& rel, const std::vector<uint8_t>& data);
  void count_file(const fs::path& p);

  // ---- maps (release.cpp) -------------------------------------------------------------------
  void write_maps();
  std::string changes_json() const;
  const World& world_of(const SceneRun& s) const { return s.changed_world ? current_ : world_; }

  // ---- frames (release_frames.cpp) ----------------------------------------------------------
  struct Task {
    int scene;
    const Frame* frame;
  };

  void render_frames();
  void render_task(const Task& task, size_t task_index);
  static std::vector<uint8_t> encode_mask(const CameraImage& img, int n);

  // ---- tables (release_tables.cpp) ----------------------------------------------------------
  std::string lidarseg_filename(const Frame& f) const;
  void write_lidarseg_table();
  void write_table(const std::string& name, const PyJson& records);
  static std::string visibility_of(int pts);
  std::string attribute_of(const Agent& a, double t) const;
  void write_tables();
  void add_log_and_scene(const SceneRun& s, ReleaseTables& tables) const;
  void add_calibrated_sensors(const SceneRun& s, ReleaseTables& tables) const;
  void add_sample_data(const SceneRun& s, ReleaseTables& tables);
  void add_instances(const SceneRun& s, ReleaseTables& tables);

  // ---- detections (release_tables.cpp) ------------------------------------------------------
  static const char* detection_name(const std::string& category);
  PyJson detection_box(const std::string& sample_token, const SceneBox& b, const std::array<double, 2>& velocity,
                       const std::string& name, double score, const std::string& attr);
  void write_detections();

  const SynthConfig& cfg_;
  const SynthRunOptions& opt_;
  uint64_t seed_;
  World world_;    // the world as built: every scene's, or with changes the prior
  World current_;  // with changes: the world from changes_date_ on
  std::vector<MapEdit> edits_;
  std::string changes_date_;
  std::vector<SceneRun> scenes_;
  SynthSummary summary_;
  std::atomic<uint64_t> files_{0};
  std::atomic<uint64_t> bytes_{0};
};

}  // namespace nsg::synth::release_detail
