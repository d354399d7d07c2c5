#pragma once
// The renderable synthetic world: the contract between the world builder (world.cpp,
// world_roads.cpp, world_surface.cpp: roads, buildings, traffic) and the sensor simulators
// (lidar_sim.cpp, camera_sim.cpp).
// Everything is in the global map frame: metres, x east, y north, z up.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace nsg::synth {

// Surface and object classes. Values are the class ids of samples/semantic-classes.json
// (the 14 classes; 255 = void), so a class image is written without a lookup.
enum class SemanticClass : uint8_t {
  kRoad = 0,
  kLaneMarking = 1,
  kCrosswalk = 2,
  kSidewalk = 3,
  kCurb = 4,
  kTerrain = 5,
  kVegetation = 6,
  kBuilding = 7,
  kCar = 8,
  kTruckBus = 9,
  kPerson = 10,
  kTwoWheeler = 11,
  kPoleSign = 12,
  kSkyOther = 13,
  kVoid = 255,
};

// What the ground is made of at a point; drives LiDAR intensity, camera colour and class.
enum class GroundMaterial : uint8_t {
  kAsphalt,
  kPaintWhite,
  kPaintYellow,
  kCrosswalkPaint,
  kSidewalk,
  kCurbTop,
  kTerrain,
  kVegetation,
};

struct GroundSample {
  GroundMaterial material = GroundMaterial::kTerrain;
  double height_m = 0.0;  // ground height (sidewalks/curbs are raised ≈ 0.15 m)
};

// The ground as a function of (x, y): material and height. Must be deterministic and
// thread-safe (const); the world builder backs it with its road/sidewalk geometry.
using GroundFunction = std::function<GroundSample(double x_m, double y_m)>;

// An oriented box standing on the ground (buildings, vehicles, pedestrians as boxes).
struct SceneBox {
  Eigen::Vector3d center_m;  // box centre (z = centre height)
  double yaw_rad = 0.0;      // heading of the box's x (length) axis, CCW from +x
  double length_m = 1.0;     // along x
  double width_m = 1.0;      // along y
  double height_m = 1.0;     // along z
  SemanticClass cls = SemanticClass::kBuilding;
  uint8_t lidar_intensity = 30;               // 0..255
  std::array<uint8_t, 3> rgb{128, 128, 128};  // base colour for the camera
};

// A vertical cylinder (poles, sign posts, tree trunks).
struct ScenePole {
  Eigen::Vector2d base_m;
  double radius_m = 0.1;
  double height_m = 5.0;
  SemanticClass cls = SemanticClass::kPoleSign;
  uint8_t lidar_intensity = 60;
  std::array<uint8_t, 3> rgb{90, 90, 90};
};

// Everything a sensor sees at one instant: the static world plus the boxes of the
// moving and parked traffic at that timestamp. `bounds_m` = [x_min, y_min, x_max, y_max]
// of the world (rays leaving it hit nothing / sky).
struct SceneSnapshot {
  GroundFunction ground;
  std::vector<SceneBox> static_boxes;   // buildings (the same for every snapshot)
  std::vector<SceneBox> dynamic_boxes;  // vehicles/people at this timestamp
  std::vector<ScenePole> poles;
  std::array<double, 4> bounds_m{};
};

}  // namespace nsg::synth
