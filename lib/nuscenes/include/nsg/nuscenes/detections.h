#pragma once
// nuScenes detection results (docs/nuscenes-input.md): {"meta": {...}, "results":
// {sample_token: [box, ...]}}, read with simdjson on-demand and validated box by box.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/token.h"

namespace nsg::nuscenes {

class Database;

// The 10 detection classes, in the devkit's order.
enum class DetectionClass : std::uint8_t {
  kCar,
  kTruck,
  kBus,
  kTrailer,
  kConstructionVehicle,
  kPedestrian,
  kMotorcycle,
  kBicycle,
  kTrafficCone,
  kBarrier
};
inline constexpr size_t kDetectionClassCount = 10;
const char* detection_class_name(DetectionClass c);
std::optional<DetectionClass> parse_detection_class(std::string_view name);
// Attribute names valid for a class ("" is always valid).
bool attribute_valid_for(DetectionClass c, std::string_view attribute_name);
// The class of a category name (vehicle.car → car, …); nullopt for ignored categories.
std::optional<DetectionClass> detection_class_of_category(std::string_view category_name);
// car, truck, bus, trailer, construction_vehicle: the classes of the vehicle layer.
bool is_vehicle_class(DetectionClass c);

inline constexpr size_t kMaxBoxesPerSample = 500;

struct DetectionMeta {
  bool use_camera = false;
  bool use_lidar = false;
  bool use_radar = false;
  bool use_map = false;
  bool use_external = false;
};

struct DetectionBox {
  Token sample_token;
  std::array<double, 3> translation{};  // global m, centre
  std::array<double, 3> size{};         // [w, l, h] m
  geometry::Quaternion rotation;        // box → global
  std::array<double, 2> velocity{};     // global m/s
  DetectionClass detection_name = DetectionClass::kCar;
  double detection_score = 0.0;  // finite, in [0, 1]
  std::string attribute_name;    // "" or valid for the class
  std::optional<std::array<double, 3>> ego_translation;
  std::optional<std::int32_t> num_pts;
};

struct DetectionSample {
  Token sample_token;
  std::vector<DetectionBox> boxes;
};

struct DetectionResults {
  std::string file;
  DetectionMeta meta;
  std::vector<DetectionSample> samples;  // in file order
  // Row in `samples` of a sample token, kNoIndex if absent.
  Index find(const Token& sample_token) const;

  TokenIndex index;  // built by read_detections
};

// Reads and validates a results file. Throws IoError / ParseError naming the file, the
// sample token and box index, and what was expected (class, score in [0,1], attribute
// valid for the class, arities, ≤ 500 boxes, box.sample_token equal to its key).
DetectionResults read_detections(const std::filesystem::path& file);

// The evaluator's requirement: the results hold exactly the given samples (every one of
// them, and no other). Throws DataError naming the results file and the first offending
// sample token.
void check_covers(const DetectionResults& results, const Database& db, std::span<const Index> sample_indices);
// All samples of the database.
void check_covers(const DetectionResults& results, const Database& db);

// Every sample of the results is a sample of the database (a results file of another
// release or split would otherwise give empty vehicle layers without a word). Throws
// DataError naming the results file and the first unknown sample token.
void check_known_samples(const DetectionResults& results, const Database& db);

}  // namespace nsg::nuscenes
