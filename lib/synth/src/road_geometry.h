#pragma once
// Reference-line primitives of the synthetic roads (straight or circular), their lateral
// offsets and local (s, d) coordinates. Internal to the synth module.
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "nsg/geometry/arcline.h"

namespace nsg::synth {

// A straight (curvature 0) or circular piece of a reference line.
struct Prim {
  geometry::Pose2 start;
  double length = 0.0;
  double curvature = 0.0;  // 1/m, positive = turning left
};

// Point at arc length s (any real s; lines extend) and lateral offset d (left positive).
inline Eigen::Vector2d prim_point(const Prim& p, double s, double d) {
  const double c = std::cos(p.start.yaw), sn = std::sin(p.start.yaw);
  if (p.curvature == 0.0) return {p.start.x + c * s - sn * d, p.start.y + sn * s + c * d};
  const double r = 1.0 / p.curvature;  // signed radius; centre on the left for r > 0
  const Eigen::Vector2d centre(p.start.x - sn * r, p.start.y + c * r);
  const double yaw = p.start.yaw + s * p.curvature;
  // The point at offset d lies on the circle of radius (r − d) around the centre.
  return {centre.x() + std::sin(yaw) * (r - d), centre.y() - std::cos(yaw) * (r - d)};
}

inline double prim_yaw(const Prim& p, double s) { return p.start.yaw + s * p.curvature; }

// (s, d) of a point relative to the primitive (for arcs, s from the angle about the centre).
inline Eigen::Vector2d prim_local(const Prim& p, const Eigen::Vector2d& q) {
  const double c = std::cos(p.start.yaw), sn = std::sin(p.start.yaw);
  const Eigen::Vector2d v(q.x() - p.start.x, q.y() - p.start.y);
  if (p.curvature == 0.0) return {c * v.x() + sn * v.y(), -sn * v.x() + c * v.y()};
  const double r = 1.0 / p.curvature;
  const Eigen::Vector2d centre(p.start.x - sn * r, p.start.y + c * r);
  const Eigen::Vector2d a = Eigen::Vector2d(p.start.x, p.start.y) - centre, b = q - centre;
  const double ang = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));  // CCW angle a → b
  const double s = ang * r;                                                // signed by turn direction
  const double d = r - (r > 0 ? 1.0 : -1.0) * b.norm();
  return {s, d};
}

// The primitive shifted sideways by d (left positive).
inline Prim offset_prim(const Prim& p, double d) {
  const Eigen::Vector2d s = prim_point(p, 0.0, d);
  Prim o;
  o.start = {s.x(), s.y(), p.start.yaw};
  o.length = p.length * (1.0 - p.curvature * d);
  o.curvature = p.curvature == 0.0 ? 0.0 : p.curvature / (1.0 - p.curvature * d);
  return o;
}

// The same primitive driven the other way.
inline Prim reverse_prim(const Prim& p) {
  const Eigen::Vector2d e = prim_point(p, p.length, 0.0);
  Prim r;
  r.start = {e.x(), e.y(), geometry::wrap_angle_devkit(prim_yaw(p, p.length) + 3.141592653589793)};
  r.length = p.length;
  r.curvature = -p.curvature;
  return r;
}

// Polygon ring of a band between two boundary curves drawn in the same direction.
inline std::vector<Eigen::Vector2d> band_ring(const std::vector<Eigen::Vector2d>& a,
                                              const std::vector<Eigen::Vector2d>& b) {
  std::vector<Eigen::Vector2d> ring(a.begin(), a.end());
  ring.insert(ring.end(), b.rbegin(), b.rend());
  return ring;
}

}  // namespace nsg::synth
