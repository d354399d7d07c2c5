// LiDAR simulator tests on hand-built scenes with known answers.
#include <gtest/gtest.h>

#include <ctime>
#include <cmath>
#include <iostream>

#include "nsg/core/error.h"
#include "nsg/synth/lidar_sim.h"
#include "test_sensors_scenes.h"

namespace nsg::synth {
namespace {

using test::flat_road_with_stripe;

geometry::Rigid3 sensor_at(double x, double y, double z) {
  geometry::Rigid3 t;
  t.translation = {x, y, z};
  return t;
}

LidarSimOptions no_roof() {
  LidarSimOptions o;
  o.roof_points = 0;
  return o;
}

// Rings 0..22 of the HDL-32E point below the horizon (ring 23 is at +0.002°).
constexpr int kDownRings = 23;

TEST(LidarSim, FlatRoadStripeIntensityAndGroundHeight) {
  const SceneSnapshot scene = flat_road_with_stripe(3.0, 0.15);
  const geometry::Rigid3 pose = sensor_at(0.0, 0.0, 1.84);
  Rng rng(7);
  const std::vector<float> pts = simulate_lidar_sweep(scene, pose, no_roof(), rng);
  ASSERT_EQ(pts.size() % 5, 0u);
  // Every downward firing hits the ground within 100 m (the flattest, ring 22, at ≈ 79 m).
  EXPECT_EQ(pts.size() / 5, static_cast<size_t>(kDownRings) * (34720 / 32));
  int on_stripe = 0, on_asphalt = 0;
  for (size_t i = 0; i < pts.size(); i += 5) {
    const Eigen::Vector3d g = pose.apply(Eigen::Vector3d(pts[i], pts[i + 1], pts[i + 2]));
    EXPECT_NEAR(g.z(), 0.0, 0.08) << "point " << i / 5;
    const double intensity = pts[i + 3];
    if (std::abs(g.x() - 3.0) < 0.12) {
      ++on_stripe;
      EXPECT_GE(intensity, 60.0);
    } else if (std::abs(g.x() - 3.0) > 0.2) {
      ++on_asphalt;
      EXPECT_LE(intensity, 15.0);
      EXPECT_GE(intensity, 5.0);
    }
  }
  EXPECT_GT(on_stripe, 30);
  EXPECT_GT(on_asphalt, 20000);
}

TEST(LidarSim, FiveFloatLayoutWithInterleavedRings) {
  const SceneSnapshot scene = flat_road_with_stripe();
  Rng rng(1);
  const std::vector<float> pts = simulate_lidar_sweep(scene, sensor_at(0, 0, 1.84), no_roof(), rng);
  ASSERT_EQ(pts.size() % 5, 0u);
  const size_t n = pts.size() / 5;
  for (size_t i = 0; i < n; ++i) {
    const float intensity = pts[5 * i + 3], ring = pts[5 * i + 4];
    ASSERT_EQ(ring, static_cast<float>(i % kDownRings)) << "point " << i;  // 0,1,…,22,0,1,…
    ASSERT_EQ(intensity, std::round(intensity));
    ASSERT_GE(intensity, 0.0f);
    ASSERT_LE(intensity, 255.0f);
  }
  // The lowest ring at −30.67° hits the ground at 1.84 / tan(30.67°) ≈ 3.10 m.
  const double r0 = std::hypot(pts[0], pts[1]);
  EXPECT_NEAR(r0, 1.84 / std::tan(30.67 * M_PI / 180.0), 0.1);
  EXPECT_NEAR(pts[1], r0, 1e-3) << "the spin starts facing +y (forward)";
}

TEST(LidarSim, BoxInFrontIsHitOnItsFace) {
  SceneSnapshot scene = flat_road_with_stripe(50.0);
  SceneBox car;
  car.center_m = {0.0, 10.0, 1.0};  // footprint x ∈ [−2, 2], y ∈ [9, 11]; near face y = 9
  car.length_m = 4.0;
  car.width_m = 2.0;
  car.height_m = 2.0;
  car.cls = SemanticClass::kCar;
  car.lidar_intensity = 50;
  scene.dynamic_boxes.push_back(car);
  const geometry::Rigid3 pose = sensor_at(0.0, 0.0, 1.84);
  Rng rng(3);
  const std::vector<float> pts = simulate_lidar_sweep(scene, pose, no_roof(), rng);
  int on_face = 0;
  for (size_t i = 0; i < pts.size(); i += 5) {
    const Eigen::Vector3d g = pose.apply(Eigen::Vector3d(pts[i], pts[i + 1], pts[i + 2]));
    const bool in_footprint = std::abs(g.x()) < 2.0 && g.y() > 8.9 && g.y() < 11.0;
    if (in_footprint && g.z() > 0.05) {
      ++on_face;
      EXPECT_NEAR(g.y(), 9.0, 0.08);  // the near face, never inside the box
      EXPECT_LE(g.z(), 2.0 + 0.01);
      EXPECT_NEAR(pts[i + 3], 50.0, 8.0);
    }
    // The box shadows the road straight behind it.
    EXPECT_FALSE(std::abs(g.x()) < 1.0 && g.y() > 11.5 && g.y() < 20.0 && g.z() < 0.1)
        << "ground point behind the box at " << g.transpose();
  }
  EXPECT_GT(on_face, 100);
  // The firing straight ahead of the nearly level ring 23 hits the face at range 9 m.
  bool found = false;
  for (size_t i = 0; i < pts.size() && !found; i += 5) {
    if (pts[i + 4] == 23.0f && std::abs(pts[i]) < 0.01) {
      EXPECT_NEAR(pts[i + 1], 9.0, 0.08);
      found = true;
    }
  }
  EXPECT_TRUE(found);
}

TEST(LidarSim, CurbFaceAndRaisedSidewalkAreNotPiercedByRays) {
  SceneSnapshot scene;
  scene.ground = [](double x, double) {
    if (x < 5.0) return GroundSample{GroundMaterial::kAsphalt, 0.0};
    if (x < 5.3) return GroundSample{GroundMaterial::kCurbTop, 0.15};
    return GroundSample{GroundMaterial::kSidewalk, 0.15};
  };
  scene.bounds_m = {-100, -100, 100, 100};
  const geometry::Rigid3 pose = sensor_at(0.0, 0.0, 1.84);
  Rng rng(5);
  LidarSimOptions options = no_roof();
  options.range_noise_m = 0.0;
  const std::vector<float> pts = simulate_lidar_sweep(scene, pose, options, rng);
  int on_sidewalk = 0, on_face = 0;
  for (size_t i = 0; i < pts.size(); i += 5) {
    const Eigen::Vector3d g = pose.apply(Eigen::Vector3d(pts[i], pts[i + 1], pts[i + 2]));
    if (g.x() > 5.001) {
      ++on_sidewalk;
      EXPECT_NEAR(g.z(), 0.15, 1e-4) << g.transpose();
    } else if (g.x() > 4.999) {
      ++on_face;
      EXPECT_GE(g.z(), -1e-4);
      EXPECT_LE(g.z(), 0.15 + 1e-4);
    } else {
      EXPECT_NEAR(g.z(), 0.0, 1e-4);
    }
  }
  EXPECT_GT(on_sidewalk, 1000);
  EXPECT_GT(on_face, 0);
}

TEST(LidarSim, RoofPointsInsideTheSquareOnLowRings) {
  const SceneSnapshot scene = flat_road_with_stripe();
  Rng rng(9);
  const LidarSimOptions options;  // 8000 roof returns
  const std::vector<float> pts = simulate_lidar_sweep(scene, sensor_at(0, 0, 1.84), options, rng);
  int roof = 0;
  for (size_t i = 0; i < pts.size(); i += 5) {
    if (std::abs(pts[i]) < 1.0 && std::abs(pts[i + 1]) < 1.0) {
      ++roof;
      EXPECT_LE(pts[i + 4], 7.0f);
      EXPECT_LT(pts[i + 2], 0.0f);
    }
  }
  EXPECT_EQ(roof, 8000);
  // Ring order stays interleaved: the first firing holds rings 0..22 (all downward).
  for (int r = 0; r < kDownRings; ++r) EXPECT_EQ(pts[5 * r + 4], static_cast<float>(r));
}

TEST(LidarSim, SameSeedSameBytesOtherSeedOtherNoise) {
  const SceneSnapshot scene = test::small_city(240.0);
  const geometry::Rigid3 pose = sensor_at(2.0, 3.5, 1.84);
  Rng a(42), b(42), c(43);
  const LidarSimOptions options;
  const auto pa = simulate_lidar_sweep(scene, pose, options, a);
  const auto pb = simulate_lidar_sweep(scene, pose, options, b);
  const auto pc = simulate_lidar_sweep(scene, pose, options, c);
  EXPECT_EQ(pa, pb);
  EXPECT_NE(pa, pc);
}

TEST(LidarSim, OptionsValidationNamesTheField) {
  LidarSimOptions o;
  o.beams = 0;
  try {
    o.validate();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.record(), "beams");
  }
  o = LidarSimOptions{};
  o.roof_points = 40000;
  EXPECT_THROW(o.validate(), ConfigError);
  o = LidarSimOptions{};
  o.range_noise_m = -1.0;
  EXPECT_THROW(o.validate(), ConfigError);
  SceneSnapshot no_ground;
  Rng rng(1);
  EXPECT_THROW(simulate_lidar_sweep(no_ground, sensor_at(0, 0, 2), LidarSimOptions{}, rng), ConfigError);
}

TEST(LidarSim, SweepTimingOnSmallCity) {
  SceneSnapshot scene = test::small_city();
  size_t ground_calls = 0;
  scene.ground = [inner = scene.ground, &ground_calls](double x, double y) {
    ++ground_calls;
    return inner(x, y);
  };
  const geometry::Rigid3 global_from_ego =
      geometry::Rigid3::from_pose({3.0, 3.0, 0.0}, geometry::quaternion_from_yaw(0.3));
  const geometry::Rigid3 pose = global_from_ego * test::ego_from_lidar_top();
  Rng rng(11);
  const double t0 = test::thread_cpu_ms();
  const SceneRaycaster caster(scene);
  const double t1 = test::thread_cpu_ms();
  const auto pts = simulate_lidar_sweep(caster, pose, LidarSimOptions{}, rng);
  const double build_ms = t1 - t0, sweep_ms = test::thread_cpu_ms() - t1;
  std::cout << "[timing] (thread CPU) raycaster build " << build_ms << " ms for " << caster.object_count()
            << " objects; sweep " << sweep_ms << " ms, " << pts.size() / 5 << " points, "
            << static_cast<double>(ground_calls) / 34720.0 << " ground calls per firing\n";
  EXPECT_GT(pts.size() / 5, 25000u);
  EXPECT_LT(sweep_ms, 2000.0);  // loose bound; the figure above is what matters
}

}  // namespace
}  // namespace nsg::synth

namespace nsg::synth {
namespace {

TEST(SceneRaycaster, PoleAndRotatedBoxAtAnalyticRanges) {
  SceneSnapshot scene = test::flat_road_with_stripe(50.0);
  ScenePole pole;
  pole.base_m = {5.0, 0.0};
  pole.radius_m = 0.1;
  pole.height_m = 4.0;
  scene.poles.push_back(pole);
  SceneBox box;  // a 2 m cube turned by 45°: its corner points at the ray
  box.center_m = {0.0, 10.0, 1.0};
  box.yaw_rad = M_PI / 4;
  box.length_m = box.width_m = box.height_m = 2.0;
  scene.static_boxes.push_back(box);
  const SceneRaycaster caster(scene);
  EXPECT_EQ(caster.object_count(), 2u);
  const Eigen::Vector3d o(0.0, 0.0, 1.0);
  const RayHit to_pole = caster.cast(o, {1.0, 0.0, 0.0}, 100.0);
  ASSERT_TRUE(to_pole.hit);
  EXPECT_EQ(to_pole.kind, RayHit::Kind::kPole);
  EXPECT_NEAR(to_pole.range_m, 4.9, 1e-9);
  EXPECT_NEAR(to_pole.normal.x(), -1.0, 1e-9);
  EXPECT_EQ(to_pole.cls, SemanticClass::kPoleSign);
  const RayHit to_box = caster.cast(o, {0.0, 1.0, 0.0}, 100.0);
  ASSERT_TRUE(to_box.hit);
  EXPECT_EQ(to_box.kind, RayHit::Kind::kBox);
  EXPECT_NEAR(to_box.range_m, 10.0 - std::sqrt(2.0), 1e-9);
  EXPECT_EQ(to_box.cls, SemanticClass::kBuilding);
  // Over the pole top (4 m): the ray passes; straight down onto its cap it hits at 4 m.
  EXPECT_FALSE(caster.cast({0.0, 0.0, 4.5}, {1.0, 0.0, 0.0}, 100.0).hit);
  const RayHit cap = caster.cast({5.0, 0.0, 6.0}, {0.0, 0.0, -1.0}, 100.0);
  ASSERT_TRUE(cap.hit);
  EXPECT_EQ(cap.kind, RayHit::Kind::kPole);
  EXPECT_NEAR(cap.point_m.z(), 4.0, 1e-9);
  // Ground straight down from 1 m, on asphalt.
  const RayHit down = caster.cast(o, {0.3, -1.0, -1.0}, 100.0);
  ASSERT_TRUE(down.hit);
  EXPECT_EQ(down.kind, RayHit::Kind::kGround);
  EXPECT_EQ(down.cls, SemanticClass::kRoad);
  EXPECT_NEAR(down.point_m.z(), 0.0, 1e-12);
}

TEST(SceneRaycaster, SensorInsideAnEgoBoxSeesOutAndWorldBoundsEndRays) {
  SceneSnapshot scene = test::flat_road_with_stripe(50.0);
  SceneBox ego;  // the sensor sits inside this box: it must not blind the sensor
  ego.center_m = {0.0, 0.0, 0.8};
  ego.length_m = 4.5;
  ego.width_m = 2.0;
  ego.height_m = 1.6;
  scene.dynamic_boxes.push_back(ego);
  const SceneRaycaster caster(scene);
  const RayHit out = caster.cast({0.0, 0.0, 1.5}, {0.0, 1.0, -0.1}, 100.0);
  ASSERT_TRUE(out.hit);
  EXPECT_EQ(out.kind, RayHit::Kind::kGround);
  EXPECT_NEAR(out.point_m.y(), 15.0, 1e-9);
  // Seen from outside, the same box is solid.
  const RayHit from_outside = caster.cast({0.0, -10.0, 1.0}, {0.0, 1.0, 0.0}, 100.0);
  ASSERT_TRUE(from_outside.hit);
  EXPECT_NEAR(from_outside.range_m, 10.0 - 1.0, 1e-9);  // the −y face (width 2 m)
  // The ground ends at the world bounds (±200 m): a shallow ray reaching z = 0 at 300 m misses.
  EXPECT_FALSE(caster.cast({0.0, 0.0, 1.5}, {0.0, 300.0, -1.5}, 1000.0).hit);
  EXPECT_TRUE(caster.cast({0.0, 0.0, 1.5}, {0.0, 150.0, -1.5}, 1000.0).hit);
  // Beyond max range: a miss.
  EXPECT_FALSE(caster.cast({0.0, 0.0, 1.5}, {0.0, 150.0, -1.5}, 100.0).hit);
}

}  // namespace
}  // namespace nsg::synth
