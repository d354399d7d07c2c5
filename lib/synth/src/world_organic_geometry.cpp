// Geometry of the organic layout (world_organic.h): bends, roads along control polylines,
// junction radii, convex hulls.
#include <algorithm>
#include <cmath>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "world_builder.h"
#include "world_organic.h"

namespace nsg::synth::world_detail {

namespace {

Prim chained(const geometry::Pose2& start, double length, double curvature) {
  Prim p;
  p.start = start;
  p.length = length;
  p.curvature = curvature;
  return p;
}

geometry::Pose2 prim_end(const Prim& p) {
  const Eigen::Vector2d e = prim_point(p, p.length, 0.0);
  return {e.x(), e.y(), prim_yaw(p, p.length)};
}

double heading(const Eigen::Vector2d& v) { return std::atan2(v.y(), v.x()); }

}  // namespace

std::vector<Prim> bend_prims(const geometry::Pose2& start, double turn_rad, double radius_m, bool spiral) {
  std::vector<Prim> out;
  const double kappa = (turn_rad > 0 ? 1.0 : -1.0) / radius_m, sweep = std::fabs(turn_rad);
  if (!spiral) {
    out.push_back(chained(start, sweep * radius_m, kappa));
    return out;
  }
  // Run-in arcs at 1/4, 2/4, 3/4 of the curvature, each of length l, turn 1.5·l·|kappa|
  // together; the run-out mirrors them.
  const double l = kSpiralShare / 3.0 * sweep * radius_m;
  const double steps[] = {0.25, 0.5, 0.75, 1.0, 0.75, 0.5, 0.25};
  geometry::Pose2 pose = start;
  for (double f : steps) {
    const double length = f == 1.0 ? (1.0 - kSpiralShare) * sweep * radius_m : l;
    out.push_back(chained(pose, length, kappa * f));
    pose = prim_end(out.back());
  }
  return out;
}

double bend_tangent_m(double turn_rad, double radius_m, bool spiral) {
  if (std::fabs(turn_rad) < 1e-9) return 0.0;
  const std::vector<Prim> prims = bend_prims({0.0, 0.0, 0.0}, turn_rad, radius_m, spiral);
  const geometry::Pose2 e = prim_end(prims.back());
  return e.x - e.y / std::tan(turn_rad);  // where the exit tangent crosses the x axis
}

namespace {

// Bend radii (≤ radius_m) that fit every leg of the polyline, or an empty vector.
std::vector<double> fitting_radii(const std::vector<double>& leg, const std::vector<double>& turn, double ext_a_m,
                                  double ext_b_m, double radius_m, bool spiral) {
  const size_t n = turn.size();
  std::vector<double> radius(n, radius_m);
  for (;;) {
    bool fits = true, shrunk = false;
    for (size_t i = 0; i + 1 < n; ++i) {
      const double t0 = i == 0 ? ext_a_m + kEndStubM : bend_tangent_m(turn[i], radius[i], spiral);
      const double t1 = i + 2 == n ? ext_b_m + kEndStubM : bend_tangent_m(turn[i + 1], radius[i + 1], spiral);
      if (t0 + t1 <= leg[i]) continue;
      fits = false;
      for (size_t v : {i, i + 1}) {
        if (v == 0 || v + 1 == n || radius[v] <= kMinBendRadiusM) continue;
        radius[v] = std::max(kMinBendRadiusM, radius[v] * 0.9);
        shrunk = true;
      }
    }
    if (fits) return radius;
    if (!shrunk) return {};
  }
}

}  // namespace

std::vector<Prim> polyline_prims(const std::vector<Eigen::Vector2d>& poly, double ext_a_m, double ext_b_m,
                                 double radius_m, bool spiral) {
  const size_t n = poly.size();
  if (n < 2) throw InternalError("", "organic layout", "a road needs two points");
  std::vector<Eigen::Vector2d> dir(n - 1);
  std::vector<double> leg(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) {
    leg[i] = (poly[i + 1] - poly[i]).norm();
    dir[i] = (poly[i + 1] - poly[i]) / leg[i];
  }
  std::vector<double> turn(n, 0.0);
  for (size_t i = 1; i + 1 < n; ++i) turn[i] = geometry::wrap_angle_devkit(heading(dir[i]) - heading(dir[i - 1]));
  // Clothoid-like bends need longer legs than single arcs: where they do not fit even at
  // the smallest radius, the road bends in single arcs.
  std::vector<double> radius = fitting_radii(leg, turn, ext_a_m, ext_b_m, radius_m, spiral);
  if (radius.empty() && spiral) radius = fitting_radii(leg, turn, ext_a_m, ext_b_m, radius_m, spiral = false);
  if (radius.empty())
    throw InternalError("", "organic layout",
                        strprintf("a road from (%.1f, %.1f) has no room for its bends", poly[0].x(), poly[0].y()));
  std::vector<Prim> prims;
  const Eigen::Vector2d s = poly[0] + dir[0] * ext_a_m;
  geometry::Pose2 pose{s.x(), s.y(), heading(dir[0])};
  for (size_t i = 1; i < n; ++i) {
    // Straight up to the next bend (or to the road's end), measured along the leg.
    const Eigen::Vector2d target =
        i + 1 < n ? poly[i] - dir[i - 1] * bend_tangent_m(turn[i], radius[i], spiral) : poly[i] - dir[i - 1] * ext_b_m;
    const double straight = dir[i - 1].dot(target - Eigen::Vector2d(pose.x, pose.y));
    if (straight > 1e-6) {
      prims.push_back(chained(pose, straight, 0.0));
      pose = prim_end(prims.back());
    }
    if (i + 1 == n || std::fabs(turn[i]) < 1e-9) continue;
    for (const Prim& p : bend_prims(pose, turn[i], radius[i], spiral)) prims.push_back(p);
    pose = prim_end(prims.back());
  }
  return prims;
}

double junction_radius_m(const std::vector<Arm>& arms, double crosswalk_m) {
  double r = 0.0;
  for (const Arm& a : arms) r = std::max(r, a.extent_m + 0.5);
  auto inside = [](const Arm& arm, const Eigen::Vector2d& p) {
    const double along = arm.dir.dot(p), across = arm.dir.x() * p.y() - arm.dir.y() * p.x();
    return along > 0.0 && std::fabs(across) < arm.extent_m;
  };
  for (;; r += 0.25) {
    if (r > 200.0) throw InternalError("", "organic layout", "no junction radius keeps its arms apart");
    bool clear = true;
    for (size_t i = 0; i < arms.size() && clear; ++i) {
      const Eigen::Vector2d n(-arms[i].dir.y(), arms[i].dir.x());
      for (size_t j = 0; j < arms.size() && clear; ++j) {
        if (i == j || arms[i].dir.dot(arms[j].dir) > std::cos(20.0 * kPi / 180.0)) continue;  // same way
        for (double s : {r, r + crosswalk_m})
          for (double d : {-arms[i].extent_m, arms[i].extent_m})
            if (inside(arms[j], arms[i].dir * s + n * d)) clear = false;
      }
    }
    if (clear) return r;
  }
}

std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (pts.size() < 3) return pts;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  return hull;
}

}  // namespace nsg::synth::world_detail
