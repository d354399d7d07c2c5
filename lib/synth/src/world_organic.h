#pragma once
// Geometry of the organic layout (world_layout_organic.cpp), internal to the synth module:
// roads planned as control polylines whose corners become bends (one arc, or a
// clothoid-like sequence of arcs of rising then falling curvature), junction radii from
// the arms' directions and widths, convex hulls for junction areas.
#include <Eigen/Core>
#include <vector>

#include "road_geometry.h"

namespace nsg::synth::world_detail {

// Turning of a bend shared by its clothoid-like run-in and run-out (the rest is one arc).
constexpr double kSpiralShare = 0.6;
// A road's straight end beyond its node distance (so bends never reach a junction area).
constexpr double kEndStubM = 2.0;
constexpr double kMinBendRadiusM = 25.0;

// The prims of a symmetric bend turning `turn_rad` (left positive) from `start`: one arc of
// `radius_m`, or with `spiral` three arcs of rising curvature, the arc, three falling.
std::vector<Prim> bend_prims(const geometry::Pose2& start, double turn_rad, double radius_m, bool spiral);

// Distance from a bend's start (and end) to the corner where its two tangents meet.
double bend_tangent_m(double turn_rad, double radius_m, bool spiral);

// The prims of a road along `poly` (first and last points on the node arms' axes), from
// `ext_a_m` after its first point to `ext_b_m` before its last, every corner a bend of at
// most `radius_m` (smaller where the legs are short; single arcs where clothoid-like bends
// do not fit). Throws InternalError when a bend does not fit even at kMinBendRadiusM.
std::vector<Prim> polyline_prims(const std::vector<Eigen::Vector2d>& poly, double ext_a_m, double ext_b_m,
                                 double radius_m, bool spiral);

// One arm of a junction: its direction out of the node and the largest lateral distance of
// its road edge from the axis through the node centre.
struct Arm {
  Eigen::Vector2d dir;
  double extent_m = 0.0;
};

// The smallest radius at which every arm's end (and crosswalk beyond it) stays outside
// every other arm's road.
double junction_radius_m(const std::vector<Arm>& arms, double crosswalk_m);

// Convex hull, counter-clockwise, no repeated first point.
std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> pts);

}  // namespace nsg::synth::world_detail
