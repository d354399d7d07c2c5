// The plan of one scene, made serially before any frame is rendered: timestamps, frames
// (key or not), tokens, file names and the annotated agents. Every draw comes from the
// scene's own Rng stream in a fixed order, so the plan never depends on threads.
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <map>

#include "nsg/core/error.h"
#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "release_writer.h"

namespace nsg::synth::release_detail {

using geometry::Pose2;

namespace {

constexpr double kAnnotationPadM = 0.05;
constexpr int64_t kMicrosecondsPerDay = int64_t{86400} * 1000000;

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

// LiDAR sweeps of the scene and the samples at its key sweeps (draws the sweeps' jitter).
void plan_lidar_and_samples(SceneRun& s, const SynthConfig& cfg, uint64_t seed, Rng& rng) {
  const int index = s.index;
  const int n_samples = cfg.scenes.samples_per_scene;
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
}

// Camera frames of every configured channel (draws the frames' jitter).
void plan_camera_frames(SceneRun& s, const SynthConfig& cfg, Rng& rng) {
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
}

// Tokens and file names of every frame (samples/ for key frames, sweeps/ for the others).
void name_frames(SceneRun& s, uint64_t seed) {
  const int index = s.index;
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
}

// Annotated agents: within range of the ego at each sample.
void plan_annotations(SceneRun& s, const SynthConfig& cfg, uint64_t seed) {
  const int index = s.index;
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
}

// Scenes a minute apart, each shifted by whole days to its capture day (0 for every scene
// with capture_days = 1, so one-day releases keep their timestamps).
int64_t scene_start_us(const SynthConfig& cfg, int index) {
  const double duration_s = (cfg.scenes.samples_per_scene - 1) * 0.5;
  return cfg.scenes.first_timestamp_us + static_cast<int64_t>(index) * static_cast<int64_t>((duration_s + 60.0) * 1e6) +
         capture_day(cfg, index) * kMicrosecondsPerDay;
}

}  // namespace

int64_t capture_day(const SynthConfig& cfg, int index) {
  return static_cast<int64_t>(index) * cfg.scenes.capture_days / cfg.scenes.count;
}

std::string scene_date(const SynthConfig& cfg, int index) {
  std::string date;
  log_name(cfg, scene_start_us(cfg, index), &date);
  return date;
}

std::string changes_date(const SynthConfig& cfg) {
  for (int i = 0; i < cfg.scenes.count; ++i)
    if (capture_day(cfg, i) >= cfg.changes.from_day) return scene_date(cfg, i);
  std::string date;
  log_name(cfg, cfg.scenes.first_timestamp_us + cfg.changes.from_day * kMicrosecondsPerDay, &date);
  return date;
}

// Plans timestamps, frames and annotated agents of one scene (serial, deterministic).
SceneRun plan_scene_run(const World& world, int index, uint64_t seed) {
  const SynthConfig& cfg = world.config;
  SceneRun s;
  s.index = index;
  Rng rng(seed, 0x1000 + static_cast<uint64_t>(index));
  const int n_samples = cfg.scenes.samples_per_scene;
  const double duration_s = (n_samples - 1) * 0.5;
  s.t0 = scene_start_us(cfg, index);
  s.token = table_token(seed, "scene", static_cast<uint64_t>(index));
  s.log_token = table_token(seed, "log", static_cast<uint64_t>(index));
  s.logfile = log_name(cfg, s.t0, &s.date);
  s.plan = plan_scene(world, duration_s + 0.5, rng);
  for (const SensorSpec& sp : sensor_specs())
    s.calib_tokens[sp.channel] = table_token(seed, "calibrated_sensor", static_cast<uint64_t>(index),
                                             hash_string(sp.channel.data(), sp.channel.size()));
  plan_lidar_and_samples(s, cfg, seed, rng);
  plan_camera_frames(s, cfg, rng);
  name_frames(s, seed);
  plan_annotations(s, cfg, seed);
  return s;
}

}  // namespace nsg::synth::release_detail
