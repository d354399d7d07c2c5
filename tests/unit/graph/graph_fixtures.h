#pragma once
// Analytic lanes for the graph tests: straight runs and circular arcs as arcline paths.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "nsg/graph/lane_graph.h"

namespace nsg::graph::test {

inline geometry::ArclinePath straight(double x, double y, double yaw, double length_m) {
  geometry::ArclinePath p;
  p.start_pose = {x, y, yaw};
  p.end_pose = {x + length_m * std::cos(yaw), y + length_m * std::sin(yaw), yaw};
  p.shape = geometry::ArclineShape::kLSL;
  p.radius_m = 999.999;
  p.segment_length_m = {0.0, length_m, 0.0};
  return p;
}

// A circular arc turning left (counter-clockwise) or right, sweeping `angle_rad`.
inline geometry::ArclinePath arc(double x, double y, double yaw, double radius_m, double angle_rad, bool left) {
  geometry::ArclinePath p;
  p.start_pose = {x, y, yaw};
  p.shape = left ? geometry::ArclineShape::kLSL : geometry::ArclineShape::kRSR;
  p.radius_m = radius_m;
  p.segment_length_m = {radius_m * angle_rad, 0.0, 0.0};
  p.end_pose = geometry::arcline_pose_at(p, p.length_m());
  return p;
}

inline LaneSource lane(const std::string& token, std::vector<geometry::ArclinePath> paths,
                       std::vector<std::string> outgoing = {}, std::vector<std::string> incoming = {},
                       bool connector = false) {
  LaneSource s;
  s.token = token;
  s.paths = std::move(paths);
  s.outgoing = std::move(outgoing);
  s.incoming = std::move(incoming);
  s.is_connector = connector;
  return s;
}

// A T-junction: A (eastbound, ends at the origin) forks into c_straight → B and
// c_right → C (southbound); D (northbound, ends at (10, −10)) turns right through c_merge into B.
inline std::vector<LaneSource> t_junction() {
  constexpr double kPi = std::numbers::pi;
  return {
      lane("A", {straight(-20, 0, 0, 20)}, {"c_straight", "c_right"}, {}),
      lane("B", {straight(20, 0, 0, 20)}, {}, {"c_straight", "c_merge"}),
      lane("C", {straight(10, -10, -kPi / 2, 20)}, {}, {"c_right"}),
      lane("D", {straight(10, -30, kPi / 2, 20)}, {"c_merge"}, {}),
      lane("c_straight", {straight(0, 0, 0, 20)}, {"B"}, {"A"}, true),
      lane("c_right", {arc(0, 0, 0, 10, kPi / 2, false)}, {"C"}, {"A"}, true),
      lane("c_merge", {arc(10, -10, kPi / 2, 10, kPi / 2, false)}, {"B"}, {"D"}, true),
  };
}

}  // namespace nsg::graph::test
