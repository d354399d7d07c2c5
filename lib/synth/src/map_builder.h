#pragma once
// Collects the records of a map expansion (v1.3) while the world is built and writes the
// JSON. Every record references only nodes/lines/polygons it created, so the devkit's
// load-time checks hold by construction. Internal to the synth module.
#include <Eigen/Core>
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nsg/core/rng.h"
#include "nsg/geometry/arcline.h"

namespace nsg::synth {

class MapBuilder {
 public:
  using Points = std::vector<Eigen::Vector2d>;
  explicit MapBuilder(Rng rng);

  std::string uuid();  // hyphenated, version-4 style, from the seeded Rng
  std::string node(const Eigen::Vector2d& p);
  std::string line(const Points& pts);
  std::string polygon(const Points& ring);

  std::string road_segment(const Points& ring, bool is_intersection);
  std::string road_block(const Points& ring, const Points& from_edge, const Points& to_edge,
                         const std::string& road_segment);
  // Lane polygon from its left/right boundaries (both in driving direction).
  std::string lane(const Points& left, const Points& right, const std::string& left_type,
                   const std::string& right_type);
  std::string lane_connector(const Points& ring);
  std::string ped_crossing(const Points& ring, const std::string& road_segment);
  std::string walkway(const Points& ring);
  std::string stop_line(const Points& ring, const std::string& type, const std::vector<std::string>& ped_crossings,
                        const std::vector<std::string>& traffic_lights, const std::string& road_block);
  std::string carpark_area(const Points& ring, double orientation_rad, const std::string& road_block);
  std::string road_divider(const Points& pts, const std::string& road_segment);
  std::string lane_divider(const Points& pts, const std::string& segment_type);
  std::string traffic_light(const Points& pts, const std::string& from_road_block,
                            const std::vector<std::string>& to_road_blocks, double yaw_rad);
  void drivable_area(const std::vector<std::string>& polygon_tokens);
  // A map change (changes.h): takes the lane or lane_connector record `token` and its polygon
  // out of the map; its arcline paths and connectivity leave with the lanes given to to_json.
  // False when there is no such record.
  bool remove_lane_record(const std::string& token);
  // A map change: the lane_divider `divider` and, in the lanes `lanes`, every divider segment
  // of type `from`, given type `to`. False when there is no such divider.
  bool retype_lane_divider(const std::string& divider, const std::vector<std::string>& lanes, const std::string& from,
                           const std::string& to);

  struct LaneTopology {
    std::string token;
    std::vector<geometry::ArclinePath> paths;
    std::vector<std::string> incoming, outgoing;
  };
  std::string to_json(const std::array<double, 2>& canvas_edge_m, const std::vector<LaneTopology>& lanes) const;

 private:
  using Json = nlohmann::ordered_json;
  Json segments(const std::vector<std::string>& nodes, const std::string& type) const;
  Rng rng_;
  std::string drivable_area_token_;
  Json node_ = Json::array(), line_ = Json::array(), polygon_ = Json::array();
  Json drivable_area_ = Json::array(), road_segment_ = Json::array(), road_block_ = Json::array();
  Json lane_ = Json::array(), ped_crossing_ = Json::array(), walkway_ = Json::array();
  Json stop_line_ = Json::array(), carpark_area_ = Json::array(), road_divider_ = Json::array();
  Json lane_divider_ = Json::array(), traffic_light_ = Json::array(), lane_connector_ = Json::array();
  std::vector<std::string> last_line_nodes_;
};

}  // namespace nsg::synth
