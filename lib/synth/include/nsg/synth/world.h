#pragma once
// The synthetic city: a street grid with a ring road (rounded corners) or the organic
// layout (config city.layout, docs/synthetic-release.md), lanes and lane
// connectors as devkit arcline paths with connectivity, the map expansion JSON, the ground
// material raster behind the GroundFunction, buildings, poles, parking slots and sidewalks.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "nsg/geometry/arcline.h"
#include "nsg/synth/config.h"
#include "nsg/synth/scene.h"

namespace nsg::synth {

// The ground as a raster of GroundMaterial codes (row 0 = south), read by nearest cell.
class GroundRaster {
 public:
  GroundRaster(double x0_m, double y0_m, double resolution_m, int width, int height);
  GroundSample sample(double x_m, double y_m) const;
  GroundMaterial material(double x_m, double y_m) const;
  bool contains_cell(int col, int row) const { return col >= 0 && row >= 0 && col < width_ && row < height_; }
  uint8_t& at(int col, int row) { return cells_[static_cast<size_t>(row) * width_ + col]; }
  double x0() const { return x0_; }
  double y0() const { return y0_; }
  double resolution() const { return res_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  double x0_, y0_, res_;
  int width_, height_;
  std::vector<uint8_t> cells_;
};

// Height of the ground for a material (sidewalks and curbs are raised).
double material_height_m(GroundMaterial m);
// True for materials on the drivable road surface (asphalt, paint, crosswalk).
bool is_drivable_material(GroundMaterial m);

// One lane or lane connector of the map.
struct LaneInfo {
  std::string token;  // hyphenated UUID
  bool is_connector = false;
  std::vector<geometry::ArclinePath> paths;
  std::vector<int> outgoing;  // indices into World::lanes
  std::vector<int> incoming;
  double length_m = 0.0;
  // For lanes: signed lateral offset of the lane centre from its road's reference line
  // (left positive, in the lane's own direction) and the road's lane count that way.
  double offset_from_centre_m = 0.0;
  bool two_way_road = false;
};

// A straight stretch of sidewalk centre line (pedestrians walk along it).
struct SidewalkPath {
  geometry::Pose2 start;
  double length_m = 0.0;
};

struct World {
  SynthConfig config;
  std::vector<LaneInfo> lanes;  // lanes first, then lane connectors
  std::shared_ptr<const GroundRaster> ground;
  std::vector<SceneBox> buildings;
  std::vector<ScenePole> poles;
  std::vector<geometry::Pose2> parking_slots;  // centre and heading of each slot
  std::vector<SidewalkPath> sidewalks;
  std::string map_json;  // maps/expansion/<location>.json contents
  std::array<double, 4> bounds_m{};

  GroundFunction ground_function() const;
  // A snapshot with the static world and the given dynamic boxes.
  SceneSnapshot snapshot(std::vector<SceneBox> dynamic_boxes) const;
};

// Builds the whole world from the config and seed (deterministic).
World build_world(const SynthConfig& config, uint64_t seed);

// Dubins path (CSC words only) from `from` to `to` with turning radius `radius_m`:
// the shortest of LSL, RSR, LSR, RSL. Throws InternalError if none exists.
geometry::ArclinePath dubins_path(const geometry::Pose2& from, const geometry::Pose2& to, double radius_m);

// Poses every ≤ `step_m` along a lane's paths (devkit discretization, joints de-duplicated).
std::vector<geometry::Pose2> lane_polyline(const LaneInfo& lane, double step_m);

}  // namespace nsg::synth
