// The sensor files of a release: every frame rendered in parallel (LiDAR sweeps with their
// lidarseg labels and num_lidar_pts counts, camera JPEGs with their class masks), each from
// its own Rng stream hashed from the frame token, so the bytes do not depend on threads.
#include <cmath>
#include <string_view>

#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/rng.h"
#include "nsg/core/strings.h"
#include "nsg/synth/camera_sim.h"
#include "nsg/synth/image_encode.h"
#include "nsg/synth/lidar_sim.h"
#include "release_writer.h"

namespace nsg::synth::release_detail {

using geometry::Pose2;
using geometry::Rigid3;

namespace {

Rigid3 ego_transform(const Pose2& p) {
  return Rigid3::from_pose({p.x, p.y, 0.0}, geometry::quaternion_from_yaw(p.yaw));
}
Rigid3 sensor_transform(const SensorSpec& s) { return Rigid3::from_pose(s.translation, s.rotation); }

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

}  // namespace

Eigen::Matrix3d intrinsic_for(const SensorSpec& sp, const CameraConfig& cam) {
  const double sx = cam.width_px / 1600.0, sy = cam.height_px / 900.0;
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = sp.intrinsic[0] * sx;
  k(1, 1) = sp.intrinsic[1] * sy;
  k(0, 2) = sp.intrinsic[2] * sx;
  k(1, 2) = sp.intrinsic[3] * sy;
  return k;
}

// ---- frames -----------------------------------------------------------------------------

void ReleaseWriter::render_frames() {
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

void ReleaseWriter::render_task(const Task& task, size_t task_index) {
  SceneRun& s = scenes_[static_cast<size_t>(task.scene)];
  const Frame& f = *task.frame;
  const double t = seconds_since(s, f.timestamp);
  const SensorSpec& sp = spec(f.channel);
  Rng rng(seed_, mix64(0x6672616d65ULL ^ (static_cast<uint64_t>(task.scene) << 40) ^
                       hash_string(f.token.data(), f.token.size())));
  (void)task_index;
  const SceneSnapshot snap = world_of(s).snapshot(boxes_at(s.plan, t));
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
std::vector<uint8_t> ReleaseWriter::encode_mask(const CameraImage& img, int n) {
  if (n == 1) return encode_png_gray8_from(img);
  const int w = (img.width_px + n - 1) / n, h = (img.height_px + n - 1) / n;
  std::vector<uint8_t> small(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      small[static_cast<size_t>(y) * w + x] = img.classes[static_cast<size_t>(y) * n * img.width_px + x * n];
  return encode_png_gray8(small.data(), w, h);
}

}  // namespace nsg::synth::release_detail
