// Camera simulator tests: the devkit projection chain lands on the right pixel.
#include <gtest/gtest.h>

#include <ctime>
#include <cmath>
#include <fstream>
#include <iostream>
#include <set>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/synth/camera_sim.h"
#include "test_sensors_scenes.h"
#include "test_support.h"

namespace nsg::synth {
namespace {

// Global → image exactly as map_pointcloud_to_image does it (docs/nuscenes-input.md),
// given the ego pose and the camera calibration as separate transforms.
struct DevkitProjection {
  bool visible = false;
  double u = 0, v = 0, depth = 0;
};
DevkitProjection devkit_project(const Eigen::Vector3d& p_global, const geometry::Rigid3& global_from_ego,
                                const geometry::Rigid3& ego_from_cam, const Eigen::Matrix3d& k, int width, int height) {
  Eigen::Vector3d p = p_global - global_from_ego.translation;  // step 5
  p = global_from_ego.rotation.transpose() * p;                // step 6
  p = p - ego_from_cam.translation;                            // step 7
  p = ego_from_cam.rotation.transpose() * p;                   // step 8
  DevkitProjection r;
  r.depth = p.z();
  const Eigen::Vector3d q = k * p;
  r.u = q.x() / p.z();
  r.v = q.y() / p.z();
  r.visible = r.depth > 1.0 && r.u > 1 && r.u < width - 1 && r.v > 1 && r.v < height - 1;
  return r;
}

int max_channel_diff(const uint8_t* rgb, const std::array<uint8_t, 3>& expected) {
  int d = 0;
  for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int{rgb[k]} - int{expected[k]}));
  return d;
}

// A camera with its optical axis level, looking along global +y from (0, 0, height).
geometry::Rigid3 level_camera_facing_north(double height_m) {
  geometry::Rigid3 t;
  t.rotation.col(0) = Eigen::Vector3d(1, 0, 0);   // image x → east
  t.rotation.col(1) = Eigen::Vector3d(0, 0, -1);  // image y → down
  t.rotation.col(2) = Eigen::Vector3d(0, 1, 0);   // optical axis → north
  t.translation = {0.0, 0.0, height_m};
  return t;
}

Eigen::Matrix3d small_intrinsic(double scale) {  // CAM_FRONT K scaled to a smaller image
  Eigen::Matrix3d k = test::cam_front_intrinsic();
  k.row(0) *= scale;
  k.row(1) *= scale;
  return k;
}

TEST(CameraSim, DevkitProjectedGroundPointsLandOnTheirMaterial) {
  const SceneSnapshot scene = test::checker_world();
  const geometry::Rigid3 global_from_ego =
      geometry::Rigid3::from_pose({10.3, -4.7, 0.0}, geometry::quaternion_from_yaw(0.35));
  const geometry::Rigid3 ego_from_cam = test::ego_from_cam_front();
  const Eigen::Matrix3d k = test::cam_front_intrinsic();
  CameraSimOptions options;
  options.pixel_noise = 0.0;
  Rng rng(1);
  const CameraImage image = render_camera(scene, global_from_ego * ego_from_cam, k, options, rng);
  ASSERT_EQ(image.width_px, 1600);
  ASSERT_EQ(image.height_px, 900);
  ASSERT_EQ(image.rgb.size(), 1600u * 900u * 3u);
  ASSERT_EQ(image.classes.size(), 1600u * 900u);
  int checked = 0;
  std::set<int> materials_seen;
  // Points on a 0.5 m lattice, at least 0.25 m from any checker edge, within 15 m depth
  // (where a pixel covers well under the margin on the ground).
  for (double x = -40.0; x <= 60.0; x += 0.5) {
    for (double y = -40.0; y <= 60.0; y += 0.5) {
      const double fx = std::fmod(x + 1000.0, 2.0), fy = std::fmod(y + 1000.0, 2.0);
      if (fx < 0.25 || fx > 1.75 || fy < 0.25 || fy > 1.75) continue;
      const DevkitProjection pr = devkit_project({x, y, 0.0}, global_from_ego, ego_from_cam, k, 1600, 900);
      if (!pr.visible || pr.depth > 15.0) continue;
      const long u = std::lround(pr.u), v = std::lround(pr.v);
      const size_t i = static_cast<size_t>(v) * 1600 + static_cast<size_t>(u);
      const GroundMaterial m = test::checker_material(x, y);
      ASSERT_EQ(image.classes[i], static_cast<uint8_t>(ground_class(m))) << "point " << x << "," << y;
      ASSERT_LE(max_channel_diff(&image.rgb[3 * i], ground_base_rgb(m)), 20) << x << "," << y;
      materials_seen.insert(static_cast<int>(m));
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
  EXPECT_EQ(materials_seen.size(), 8u);
}

TEST(CameraSim, PaintedStripePixelIsLaneMarkingAndWhite) {
  const SceneSnapshot scene = test::flat_road_with_stripe(1.0, 0.15);
  const geometry::Rigid3 cam = level_camera_facing_north(1.5);
  const Eigen::Matrix3d k = test::cam_front_intrinsic();
  CameraSimOptions options;
  Rng rng(2);
  const CameraImage image = render_camera(scene, cam, k, options, rng);
  const geometry::Rigid3 identity;
  for (double y : {6.0, 8.0, 12.0}) {  // nearer points fall below the image
    const DevkitProjection stripe = devkit_project({1.0, y, 0.0}, cam, identity, k, 1600, 900);
    ASSERT_TRUE(stripe.visible);
    const size_t i = static_cast<size_t>(std::lround(stripe.v)) * 1600 + std::lround(stripe.u);
    EXPECT_EQ(image.classes[i], static_cast<uint8_t>(SemanticClass::kLaneMarking));
    EXPECT_LE(max_channel_diff(&image.rgb[3 * i], ground_base_rgb(GroundMaterial::kPaintWhite)), 10);
    const DevkitProjection road = devkit_project({-1.0, y, 0.0}, cam, identity, k, 1600, 900);
    const size_t j = static_cast<size_t>(std::lround(road.v)) * 1600 + std::lround(road.u);
    EXPECT_EQ(image.classes[j], static_cast<uint8_t>(SemanticClass::kRoad));
    EXPECT_LE(max_channel_diff(&image.rgb[3 * j], ground_base_rgb(GroundMaterial::kAsphalt)), 10);
  }
}

TEST(CameraSim, SkyAboveTheHorizonGroundBelow) {
  const SceneSnapshot scene = test::flat_road_with_stripe(50.0);
  const Eigen::Matrix3d k = small_intrinsic(0.25);  // 400 x 225, cy ≈ 122.9
  CameraSimOptions options;
  options.width_px = 400;
  options.height_px = 225;
  Rng rng(3);
  const CameraImage image = render_camera(scene, level_camera_facing_north(1.5), k, options, rng);
  const double cy = k(1, 2);
  for (int v = 0; v < options.height_px; ++v) {
    for (int u = 0; u < options.width_px; ++u) {
      const size_t i = static_cast<size_t>(v) * options.width_px + u;
      if (v < cy - 1.0) {
        ASSERT_EQ(image.classes[i], static_cast<uint8_t>(SemanticClass::kSkyOther)) << u << "," << v;
        ASSERT_GT(image.rgb[3 * i + 2], image.rgb[3 * i]) << "sky is blue-ish";
      } else if (v > cy + 20.0) {  // ground closer than 1.5·316.6/20 ≈ 24 m
        ASSERT_EQ(image.classes[i], static_cast<uint8_t>(SemanticClass::kRoad)) << u << "," << v;
      }
    }
  }
  // The gradient: the top row is a deeper blue than the row just above the horizon.
  const size_t top = 200, near_horizon = static_cast<size_t>(cy - 3) * 400 + 200;
  EXPECT_LT(image.rgb[3 * top], image.rgb[3 * near_horizon]);
}

TEST(CameraSim, BoxFacesAreClassedAndShadedByNormal) {
  SceneSnapshot scene = test::flat_road_with_stripe(50.0);
  SceneBox car;
  car.center_m = {0.0, 12.0, 0.8};
  car.yaw_rad = 0.6;
  car.length_m = 4.5;
  car.width_m = 1.9;
  car.height_m = 1.6;
  car.cls = SemanticClass::kCar;
  car.rgb = {40, 80, 200};
  scene.dynamic_boxes.push_back(car);
  const geometry::Rigid3 cam = level_camera_facing_north(1.5);
  const Eigen::Matrix3d k = test::cam_front_intrinsic();
  CameraSimOptions options;
  options.pixel_noise = 0.0;
  Rng rng(4);
  const CameraImage image = render_camera(scene, cam, k, options, rng);
  // Centres of the two faces the camera sees: the −x face (rear) and the −y face (side).
  const double c = std::cos(car.yaw_rad), s = std::sin(car.yaw_rad);
  const Eigen::Vector3d rear = car.center_m + Eigen::Vector3d(-c, -s, 0) * (car.length_m / 2);
  const Eigen::Vector3d side = car.center_m + Eigen::Vector3d(s, -c, 0) * (car.width_m / 2);
  const geometry::Rigid3 identity;
  std::array<std::array<uint8_t, 3>, 2> colours{};
  int f = 0;
  for (const Eigen::Vector3d& p : {rear, side}) {
    const DevkitProjection pr = devkit_project(p, cam, identity, k, 1600, 900);
    ASSERT_TRUE(pr.visible);
    const size_t i = static_cast<size_t>(std::lround(pr.v)) * 1600 + std::lround(pr.u);
    EXPECT_EQ(image.classes[i], static_cast<uint8_t>(SemanticClass::kCar));
    colours[f++] = {image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]};
    EXPECT_LE(image.rgb[3 * i + 2], 200);  // shaded, never brighter than the base colour
    EXPECT_GT(image.rgb[3 * i + 2], image.rgb[3 * i]);
  }
  EXPECT_NE(colours[0], colours[1]) << "faces with different normals get different shades";
}

TEST(CameraSim, LabelNoiseFlipsTheRequestedFractionInBlobs) {
  const SceneSnapshot scene = test::small_city(240.0);
  const geometry::Rigid3 cam =
      geometry::Rigid3::from_pose({2.0, 3.0, 0.0}, geometry::quaternion_from_yaw(0.2)) * test::ego_from_cam_front();
  const Eigen::Matrix3d k = small_intrinsic(0.25);
  CameraSimOptions clean;
  clean.width_px = 400;
  clean.height_px = 225;
  CameraSimOptions noisy = clean;
  noisy.label_noise_rate = 0.1;
  Rng r1(5), r2(5);
  const CameraImage a = render_camera(scene, cam, k, clean, r1);
  const CameraImage b = render_camera(scene, cam, k, noisy, r2);
  EXPECT_EQ(a.rgb, b.rgb) << "label noise leaves the picture alone";
  const int w = 400, h = 225;
  std::vector<uint8_t> flipped(a.classes.size());
  size_t n_flipped = 0;
  for (size_t i = 0; i < a.classes.size(); ++i) {
    flipped[i] = a.classes[i] != b.classes[i];
    n_flipped += flipped[i];
  }
  EXPECT_NEAR(static_cast<double>(n_flipped) / a.classes.size(), 0.1, 0.005);
  // Blobs, not salt-and-pepper: most flipped pixels have a flipped 4-neighbour.
  size_t with_neighbour = 0;
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      if (flipped[i] && (flipped[i - 1] || flipped[i + 1] || flipped[i - w] || flipped[i + w])) ++with_neighbour;
    }
  EXPECT_GT(static_cast<double>(with_neighbour), 0.8 * n_flipped);
  for (uint8_t cls : b.classes) EXPECT_LT(cls, 14);
}

TEST(CameraSim, SameSeedSameBytesOtherSeedOtherNoise) {
  const SceneSnapshot scene = test::small_city(240.0);
  const geometry::Rigid3 cam = level_camera_facing_north(1.5);
  const Eigen::Matrix3d k = small_intrinsic(0.2);
  CameraSimOptions options;
  options.width_px = 320;
  options.height_px = 180;
  options.label_noise_rate = 0.05;
  Rng a(8), b(8), c(9);
  const CameraImage ia = render_camera(scene, cam, k, options, a);
  const CameraImage ib = render_camera(scene, cam, k, options, b);
  const CameraImage ic = render_camera(scene, cam, k, options, c);
  EXPECT_EQ(ia.rgb, ib.rgb);
  EXPECT_EQ(ia.classes, ib.classes);
  EXPECT_NE(ia.rgb, ic.rgb);
  EXPECT_NE(ia.classes, ic.classes);
}

TEST(CameraSim, OptionsValidationNamesTheField) {
  CameraSimOptions o;
  o.label_noise_rate = 2.0;
  try {
    o.validate();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.record(), "label_noise_rate");
  }
  const SceneSnapshot scene = test::flat_road_with_stripe();
  Rng rng(1);
  EXPECT_THROW(render_camera(scene, geometry::Rigid3{}, Eigen::Matrix3d::Zero(), CameraSimOptions{}, rng), ConfigError);
}

TEST(CameraSim, FullSizeTimingOnSmallCity) {
  SceneSnapshot scene = test::small_city();
  size_t ground_calls = 0;
  scene.ground = [inner = scene.ground, &ground_calls](double x, double y) {
    ++ground_calls;
    return inner(x, y);
  };
  const geometry::Rigid3 cam =
      geometry::Rigid3::from_pose({3.0, 3.0, 0.0}, geometry::quaternion_from_yaw(0.3)) * test::ego_from_cam_front();
  const SceneRaycaster caster(scene);
  Rng rng(12);
  const double t0 = test::thread_cpu_ms();
  const CameraImage image = render_camera(caster, cam, test::cam_front_intrinsic(), CameraSimOptions{}, rng);
  const double ms = test::thread_cpu_ms() - t0;
  std::array<size_t, 14> histogram{};
  for (uint8_t cls : image.classes) ++histogram.at(cls);
  std::cout << "[timing] (thread CPU) render 1600x900 " << ms << " ms, "
            << static_cast<double>(ground_calls) / (1600.0 * 900.0) << " ground calls per pixel; classes:";
  for (size_t c = 0; c < histogram.size(); ++c)
    std::cout << ' ' << nsg::kSemanticClasses[c].name << '=' << histogram[c];
  std::cout << '\n';
  EXPECT_GT(histogram[static_cast<size_t>(SemanticClass::kRoad)], 100000u);
  EXPECT_GT(histogram[static_cast<size_t>(SemanticClass::kSkyOther)], 10000u);
  EXPECT_LT(ms, 10000.0);  // loose bound; the figure above is what matters
}

TEST(SemanticClasses, JsonFileMatchesTheEnumAndPalette) {
  std::ifstream in(nsg::test::source_dir() / "samples" / "semantic-classes.json");
  ASSERT_TRUE(in.good());
  const nlohmann::json doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc.at("schema_version"), "1");
  EXPECT_EQ(doc.at("void_id"), 255);
  const auto& classes = doc.at("classes");
  ASSERT_EQ(classes.size(), 14u);
  std::set<std::array<int, 3>> colours;
  for (size_t i = 0; i < classes.size(); ++i) {
    const auto& c = classes[i];
    const SemanticClassInfo& info = nsg::kSemanticClasses[i];
    EXPECT_EQ(c.at("id").get<int>(), static_cast<int>(i));
    EXPECT_EQ(info.id, i);
    EXPECT_EQ(c.at("name").get<std::string>(), std::string(info.name));
    const auto rgb = c.at("color").get<std::array<int, 3>>();
    EXPECT_EQ(rgb, (std::array<int, 3>{info.color[0], info.color[1], info.color[2]}));
    colours.insert(rgb);
  }
  EXPECT_EQ(colours.size(), 14u) << "colours must be distinct";
  using Rgb3 = std::array<int, 3>;
  const auto colour_of = [&](size_t i) { return classes[i].at("color").get<Rgb3>(); };
  EXPECT_EQ(classes[0].at("name"), "road");
  EXPECT_EQ(colour_of(0), (Rgb3{200, 100, 50}));
  EXPECT_EQ(colour_of(1), (Rgb3{230, 120, 10}));
  EXPECT_EQ(colour_of(3), (Rgb3{255, 220, 200}));
  EXPECT_EQ(colour_of(4), (Rgb3{200, 49, 254}));
  EXPECT_EQ(colour_of(5), (Rgb3{255, 0, 0}));
  EXPECT_EQ(classes[13].at("name"), "sky_other");
}

}  // namespace
}  // namespace nsg::synth
