#pragma once
// Camera simulation: renders an RGB image and a per-pixel semantic class image of a
// SceneSnapshot by casting one ray per pixel centre (the exact inverse of the devkit's
// projection, docs/nuscenes-input.md).
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "nsg/core/semantic_classes.h"
#include "nsg/core/rng.h"
#include "nsg/geometry/transform.h"
#include "nsg/synth/lidar_sim.h"
#include "nsg/synth/scene.h"

namespace nsg::synth {

struct CameraSimOptions {
  int width_px = 1600, height_px = 900;
  double label_noise_rate = 0.0;  // fraction of pixels whose class is flipped (in blobs)
  double max_depth_m = 250.0;
  // Added: sensor noise, uniform in ±pixel_noise (per channel, 0..255 scale).
  double pixel_noise = 2.0;
  RaycastOptions raycast;  // added: ground band and marching steps
  void validate() const;   // ConfigError naming the bad field
};

struct CameraImage {
  int width_px = 0, height_px = 0;
  std::vector<uint8_t> rgb;      // row-major RGB8
  std::vector<uint8_t> classes;  // SemanticClass ids, 255 = void
};

// Pinhole camera (x right, y down, z forward), K = [[fx,0,cx],[0,fy,cy],[0,0,1]].
// Pixel (i, j) (column i, row j) is the ray through the image point u = i, v = j, i.e. a
// point the devkit projects to (u, v) = ((K p).x / z, (K p).y / z) lies in pixel
// (round(u), round(v)) — pixel centres at integer coordinates, as matplotlib's imshow
// draws the devkit's overlays. Rays that hit nothing (sky, beyond the world bounds or
// max_depth_m) get class kSkyOther: a blue gradient upwards, haze grey downwards. Label
// noise changes only `classes`, never `rgb`. Single-threaded; the Rng is consumed in
// pixel order (one draw per pixel when pixel_noise > 0, then the label-noise blobs).
CameraImage render_camera(const SceneSnapshot& scene, const geometry::Rigid3& global_from_camera,
                          const Eigen::Matrix3d& intrinsic, const CameraSimOptions& options, Rng& rng);
// Same with a ray caster built once for the snapshot (reuse it for the six cameras).
CameraImage render_camera(const SceneRaycaster& caster, const geometry::Rigid3& global_from_camera,
                          const Eigen::Matrix3d& intrinsic, const CameraSimOptions& options, Rng& rng);

// The colour the renderer gives a ground material before texture and noise; tests and
// the world check pixels against it.
std::array<uint8_t, 3> ground_base_rgb(GroundMaterial material);
// The semantic class of a ground material.
SemanticClass ground_class(GroundMaterial material);

// The classes' names and palette: nsg::kSemanticClasses (nsg/core/semantic_classes.h).

}  // namespace nsg::synth
