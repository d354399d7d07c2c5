#pragma once
// Hand-built scenes with known answers for the sensor simulator tests.
#include <cmath>
#include <ctime>

#include "nsg/geometry/transform.h"
#include "nsg/synth/scene.h"

namespace nsg::synth::test {

// CPU time of the calling thread (ms): a fair single-core figure on a busy machine.
inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// Flat asphalt at z = 0 with one white paint stripe |x − stripe_x| < half_width.
inline SceneSnapshot flat_road_with_stripe(double stripe_x_m = 3.0, double half_width_m = 0.15) {
  SceneSnapshot scene;
  scene.ground = [=](double x, double) {
    GroundSample s;
    s.material = std::abs(x - stripe_x_m) < half_width_m ? GroundMaterial::kPaintWhite : GroundMaterial::kAsphalt;
    s.height_m = 0.0;
    return s;
  };
  scene.bounds_m = {-200.0, -200.0, 200.0, 200.0};
  return scene;
}

// The ground material of a 2 m checkerboard of all eight materials (all at z = 0).
inline GroundMaterial checker_material(double x, double y) {
  const long i = static_cast<long>(std::floor(x / 2.0)) + 3 * static_cast<long>(std::floor(y / 2.0));
  return static_cast<GroundMaterial>(((i % 8) + 8) % 8);
}

inline SceneSnapshot checker_world() {
  SceneSnapshot scene;
  scene.ground = [](double x, double y) { return GroundSample{checker_material(x, y), 0.0}; };
  scene.bounds_m = {-300.0, -300.0, 300.0, 300.0};
  return scene;
}

// A small city: 60 m blocks, 14 m roads with a dashed centre line, 3 m raised sidewalks
// (0.15 m, curb strip 0.3 m), terrain inside blocks, a building per block, parked cars
// along the curbs and poles on the sidewalks. Roughly the density of the synthetic city.
inline SceneSnapshot small_city(double size_m = 480.0) {
  constexpr double kBlock = 60.0, kRoadHalf = 7.0, kWalk = 3.0, kCurb = 0.3;
  SceneSnapshot scene;
  auto road_offset = [=](double v) {  // signed distance to the nearest road centre line
    return v - kBlock * std::round(v / kBlock);
  };
  scene.ground = [=](double x, double y) {
    const double ox = road_offset(x), oy = road_offset(y);
    const double ax = std::abs(ox), ay = std::abs(oy);
    const double a = std::min(ax, ay);  // distance to the nearest road centre
    GroundSample s;
    if (a < kRoadHalf) {
      s.height_m = 0.0;
      const bool along_x = ay < ax;  // the road running along x (its centre line is y ≈ 0)
      const double across = along_x ? ay : ax, along = along_x ? x : y;
      const bool in_junction = ax < kRoadHalf && ay < kRoadHalf;
      const bool dash = std::fmod(std::abs(along), 6.0) < 3.0;
      s.material = (!in_junction && across < 0.075 && dash) ? GroundMaterial::kPaintWhite : GroundMaterial::kAsphalt;
    } else if (a < kRoadHalf + kCurb) {
      s = {GroundMaterial::kCurbTop, 0.15};
    } else if (a < kRoadHalf + kWalk) {
      s = {GroundMaterial::kSidewalk, 0.15};
    } else {
      s = {GroundMaterial::kTerrain, 0.05};
    }
    return s;
  };
  const double half = 0.5 * size_m;
  scene.bounds_m = {-half, -half, half, half};
  int k = 0;
  for (double bx = -half + kBlock / 2; bx < half; bx += kBlock) {
    for (double by = -half + kBlock / 2; by < half; by += kBlock, ++k) {
      SceneBox b;
      b.center_m = {bx, by, 6.0 + (k % 4)};
      b.length_m = 30.0;
      b.width_m = 24.0 + (k % 3);
      b.height_m = 2.0 * b.center_m.z();
      b.rgb = {150, 130, 120};
      scene.static_boxes.push_back(b);
      for (int c = 0; c < 4; ++c) {  // parked cars along the block's south curb
        SceneBox car;
        car.center_m = {bx - 18.0 + 9.0 * c, by - kBlock / 2 + kRoadHalf - 1.2, 0.8};
        car.length_m = 4.5;
        car.width_m = 1.9;
        car.height_m = 1.6;
        car.cls = SemanticClass::kCar;
        car.lidar_intensity = 45;
        car.rgb = {30, 60, 160};
        scene.dynamic_boxes.push_back(car);
      }
      for (int p = 0; p < 3; ++p) {
        ScenePole pole;
        pole.base_m = {bx - 20.0 + 20.0 * p, by - kBlock / 2 + kRoadHalf + 1.5};
        scene.poles.push_back(pole);
      }
    }
  }
  return scene;
}

// The nuScenes CAM_FRONT calibration of log n015 (docs/nuscenes-input.md) and its K.
inline geometry::Rigid3 ego_from_cam_front() {
  return geometry::Rigid3::from_pose(
      {1.70079118954, 0.0159456324149, 1.51095763913},
      geometry::Quaternion{0.4998015430569128, -0.5030316162024876, 0.4997798114386805, -0.49737083824542755});
}
inline Eigen::Matrix3d cam_front_intrinsic() {
  Eigen::Matrix3d k;
  k << 1266.417203046554, 0, 816.2670197447984, 0, 1266.417203046554, 491.50706579294757, 0, 0, 1;
  return k;
}
inline geometry::Rigid3 ego_from_lidar_top() {
  return geometry::Rigid3::from_pose(
      {0.943713, 0.0, 1.84023},
      geometry::Quaternion{0.7077955119163518, -0.006492242056004365, 0.010646214713995808, -0.7063073142877817});
}

}  // namespace nsg::synth::test
