// LiDAR simulation and the shared scene ray caster (camera_sim.cpp uses it too).
#include "nsg/synth/lidar_sim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "nsg/core/error.h"
#include "nsg/synth/camera_sim.h"  // ground_class()

namespace nsg::synth {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

void require(bool ok, const char* record, const std::string& expected) {
  if (!ok) throw ConfigError("", record, expected);
}

bool finite(double v) { return std::isfinite(v); }

using XyBounds = std::array<double, 4>;  // x0, y0, x1, y1 (m)

// The xy bounding box of a box turned by its yaw.
XyBounds yawed_box_bounds(const SceneBox& box, double cos_yaw, double sin_yaw) {
  const double ex = 0.5 * (std::abs(cos_yaw) * box.length_m + std::abs(sin_yaw) * box.width_m);
  const double ey = 0.5 * (std::abs(sin_yaw) * box.length_m + std::abs(cos_yaw) * box.width_m);
  return {box.center_m.x() - ex, box.center_m.y() - ey, box.center_m.x() + ex, box.center_m.y() + ey};
}

XyBounds pole_bounds(const ScenePole& p) {
  return {p.base_m.x() - p.radius_m, p.base_m.y() - p.radius_m, p.base_m.x() + p.radius_m, p.base_m.y() + p.radius_m};
}

XyBounds union_bounds(const std::vector<XyBounds>& boxes) {
  double x0 = kInf, y0 = kInf, x1 = -kInf, y1 = -kInf;
  for (const XyBounds& b : boxes) {
    x0 = std::min(x0, b[0]);
    y0 = std::min(y0, b[1]);
    x1 = std::max(x1, b[2]);
    y1 = std::max(y1, b[3]);
  }
  return {x0, y0, x1, y1};
}

// The grid's cell edge over a w × h extent: the requested one, or (0) a few objects per
// cell but not a huge grid; at most 4 million cells either way.
double grid_cell_m(double requested_m, double w, double h, size_t n_objects) {
  double cell = requested_m;
  if (cell <= 0.0) {  // a few objects per cell, but not a huge grid
    cell = std::clamp(std::sqrt(w * h / static_cast<double>(n_objects)), 2.0, 50.0);
  }
  return std::max(cell, std::sqrt(w * h / 4.0e6));
}

// The uniform grid of the objects' bounding boxes, as CSR: cell c lists the boxes
// items[start[c] .. start[c + 1]), in box order.
struct ObjectGrid {
  double x0, y0, cell;
  int nx, ny;

  // The cells a box overlaps, clamped to the grid.
  void cell_range(const XyBounds& bb, int& ix0, int& iy0, int& ix1, int& iy1) const {
    ix0 = std::clamp(static_cast<int>(std::floor((bb[0] - x0) / cell)), 0, nx - 1);
    iy0 = std::clamp(static_cast<int>(std::floor((bb[1] - y0) / cell)), 0, ny - 1);
    ix1 = std::clamp(static_cast<int>(std::floor((bb[2] - x0) / cell)), 0, nx - 1);
    iy1 = std::clamp(static_cast<int>(std::floor((bb[3] - y0) / cell)), 0, ny - 1);
  }

  void fill(const std::vector<XyBounds>& boxes, std::vector<uint32_t>& start, std::vector<uint32_t>& items) const {
    const size_t n_cells = static_cast<size_t>(nx) * static_cast<size_t>(ny);
    std::vector<uint32_t> counts(n_cells + 1, 0);
    for (size_t i = 0; i < boxes.size(); ++i) {
      int ix0, iy0, ix1, iy1;
      cell_range(boxes[i], ix0, iy0, ix1, iy1);
      for (int iy = iy0; iy <= iy1; ++iy)
        for (int ix = ix0; ix <= ix1; ++ix) ++counts[static_cast<size_t>(iy) * nx + ix + 1];
    }
    for (size_t c = 0; c < n_cells; ++c) counts[c + 1] += counts[c];
    start = counts;
    items.resize(start.back());
    std::vector<uint32_t> next(start.begin(), start.end() - 1);
    for (size_t i = 0; i < boxes.size(); ++i) {
      int ix0, iy0, ix1, iy1;
      cell_range(boxes[i], ix0, iy0, ix1, iy1);
      for (int iy = iy0; iy <= iy1; ++iy)
        for (int ix = ix0; ix <= ix1; ++ix) items[next[static_cast<size_t>(iy) * nx + ix]++] = static_cast<uint32_t>(i);
    }
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------
// Options

void RaycastOptions::validate() const {
  require(finite(ground_min_height_m) && finite(ground_max_height_m) && ground_min_height_m < ground_max_height_m,
          "raycast.ground_min_height_m", "finite ground_min_height_m < ground_max_height_m");
  require(finite(min_step_m) && min_step_m > 0.0, "raycast.min_step_m", "a step > 0 m");
  require(finite(max_step_m) && max_step_m >= min_step_m, "raycast.max_step_m", "a step >= min_step_m");
  require(finite(max_drop_per_step_m) && max_drop_per_step_m > 0.0, "raycast.max_drop_per_step_m", "a height > 0 m");
  require(finite(grid_cell_m) && grid_cell_m >= 0.0, "raycast.grid_cell_m", "a cell size >= 0 m (0 = automatic)");
}

void LidarSimOptions::validate() const {
  require(beams >= 1 && beams <= 256, "beams", "1..256 beams");
  require(finite(elevation_min_deg) && finite(elevation_max_deg) && elevation_min_deg >= -90.0 &&
              elevation_max_deg <= 90.0 && elevation_min_deg <= elevation_max_deg,
          "elevation_min_deg", "-90 <= elevation_min_deg <= elevation_max_deg <= 90");
  require(points_per_sweep >= beams, "points_per_sweep", "at least one firing per beam");
  require(finite(max_range_m) && max_range_m > 0.0, "max_range_m", "a range > 0 m");
  require(finite(range_noise_m) && range_noise_m >= 0.0, "range_noise_m", "a sigma >= 0 m");
  require(roof_points >= 0 && roof_points <= points_per_sweep, "roof_points", "0..points_per_sweep roof returns");
  require(finite(roof_depth_m) && roof_depth_m > 0.0 && roof_depth_m < 5.0, "roof_depth_m", "a depth in (0, 5) m");
  raycast.validate();
}

// ---------------------------------------------------------------------------------------
// Ray caster

SceneRaycaster::SceneRaycaster(const SceneSnapshot& scene, const RaycastOptions& options)
    : scene_(scene), options_(options) {
  options_.validate();
  if (!scene.ground) throw ConfigError("", "scene.ground", "a ground function");

  // Objects with their xy bounding boxes.
  std::vector<XyBounds> aabbs;
  auto add_box = [&](const SceneBox& box) {
    Object o;
    o.box = &box;
    o.cos_yaw = std::cos(box.yaw_rad);
    o.sin_yaw = std::sin(box.yaw_rad);
    o.z_min = box.center_m.z() - 0.5 * box.height_m;
    o.z_max = box.center_m.z() + 0.5 * box.height_m;
    aabbs.push_back(yawed_box_bounds(box, o.cos_yaw, o.sin_yaw));
    objects_.push_back(o);
  };
  for (const auto& b : scene.static_boxes) add_box(b);
  for (const auto& b : scene.dynamic_boxes) add_box(b);
  for (const auto& p : scene.poles) {
    Object o;
    o.is_pole = true;
    o.pole = &p;
    o.z_min = scene.ground(p.base_m.x(), p.base_m.y()).height_m;  // stands on the ground
    o.z_max = o.z_min + p.height_m;
    aabbs.push_back(pole_bounds(p));
    objects_.push_back(o);
  }
  if (objects_.empty()) return;

  objects_z_max_ = -kInf;
  objects_z_min_ = kInf;
  for (const Object& o : objects_) {
    objects_z_min_ = std::min(objects_z_min_, o.z_min);
    objects_z_max_ = std::max(objects_z_max_, o.z_max);
  }
  const XyBounds extent = union_bounds(aabbs);
  const double x0 = extent[0], y0 = extent[1], x1 = extent[2], y1 = extent[3];
  if (!(finite(x0) && finite(y0) && finite(x1) && finite(y1))) {
    throw ConfigError("", "scene boxes/poles", "finite object positions and sizes");
  }
  const double w = std::max(x1 - x0, 1e-3), h = std::max(y1 - y0, 1e-3);
  const double cell = grid_cell_m(options_.grid_cell_m, w, h, objects_.size());
  cell_m_ = cell;
  grid_x0_ = x0;
  grid_y0_ = y0;
  grid_nx_ = std::max(1, static_cast<int>(std::ceil(w / cell)));
  grid_ny_ = std::max(1, static_cast<int>(std::ceil(h / cell)));
  ObjectGrid{x0, y0, cell, grid_nx_, grid_ny_}.fill(aabbs, cell_start_, cell_items_);
}

bool SceneRaycaster::clip_to_bounds(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double& t_min,
                                    double& t_max) const {
  const auto& b = scene_.bounds_m;
  if (!(b[2] > b[0] && b[3] > b[1])) return t_min <= t_max;  // unset bounds: unbounded world
  for (int axis = 0; axis < 2; ++axis) {
    const double lo = b[axis], hi = b[axis + 2];
    if (std::abs(d[axis]) < 1e-15) {
      if (o[axis] < lo || o[axis] > hi) return false;
      continue;
    }
    double ta = (lo - o[axis]) / d[axis], tb = (hi - o[axis]) / d[axis];
    if (ta > tb) std::swap(ta, tb);
    t_min = std::max(t_min, ta);
    t_max = std::min(t_max, tb);
  }
  return t_min <= t_max;
}

bool SceneRaycaster::intersect(const Object& object, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                               double t_max, RayHit& hit) const {
  if (!object.is_pole) {
    const SceneBox& box = *object.box;
    const double c = object.cos_yaw, s = object.sin_yaw;
    const Eigen::Vector3d p = o - box.center_m;
    // Into the box frame (rotate by −yaw).
    const double lo[3] = {c * p.x() + s * p.y(), -s * p.x() + c * p.y(), p.z()};
    const double ld[3] = {c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z()};
    const double half[3] = {0.5 * box.length_m, 0.5 * box.width_m, 0.5 * box.height_m};
    if (std::abs(lo[0]) < half[0] && std::abs(lo[1]) < half[1] && std::abs(lo[2]) < half[2]) {
      return false;  // the sensor is inside this box (e.g. the ego vehicle): ignore it
    }
    double t_enter = -kInf, t_exit = kInf;
    int axis_enter = -1;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(ld[a]) < 1e-15) {
        if (std::abs(lo[a]) > half[a]) return false;
        continue;
      }
      double ta = (-half[a] - lo[a]) / ld[a], tb = (half[a] - lo[a]) / ld[a];
      if (ta > tb) std::swap(ta, tb);
      if (ta > t_enter) {
        t_enter = ta;
        axis_enter = a;
      }
      t_exit = std::min(t_exit, tb);
    }
    if (axis_enter < 0 || t_enter > t_exit || t_enter <= t_min || t_enter > t_max) return false;
    Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
    n_local[axis_enter] = ld[axis_enter] > 0 ? -1.0 : 1.0;
    hit.hit = true;
    hit.range_m = t_enter;
    hit.point_m = o + t_enter * d;
    hit.normal = Eigen::Vector3d(c * n_local.x() - s * n_local.y(), s * n_local.x() + c * n_local.y(), n_local.z());
    hit.kind = RayHit::Kind::kBox;
    hit.cls = box.cls;
    hit.lidar_intensity = box.lidar_intensity;
    hit.rgb = box.rgb;
    return true;
  }
  const ScenePole& pole = *object.pole;
  const double px = o.x() - pole.base_m.x(), py = o.y() - pole.base_m.y();
  const double r2 = pole.radius_m * pole.radius_m;
  const double c_term = px * px + py * py - r2;
  if (c_term < 0.0 && o.z() >= object.z_min && o.z() <= object.z_max) return false;  // inside
  double best = kInf;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a > 1e-18) {
    const double b = 2.0 * (px * d.x() + py * d.y());
    const double disc = b * b - 4.0 * a * c_term;
    if (disc >= 0.0) {
      const double t = (-b - std::sqrt(disc)) / (2.0 * a);
      const double z = o.z() + t * d.z();
      if (t > t_min && t <= t_max && z >= object.z_min && z <= object.z_max) {
        best = t;
        normal = Eigen::Vector3d(px + t * d.x(), py + t * d.y(), 0.0).normalized();
      }
    }
  }
  if (d.z() < 0.0 && o.z() > object.z_max) {  // the top cap
    const double t = (object.z_max - o.z()) / d.z();
    const double qx = px + t * d.x(), qy = py + t * d.y();
    if (t > t_min && t <= t_max && t < best && qx * qx + qy * qy <= r2) {
      best = t;
      normal = Eigen::Vector3d::UnitZ();
    }
  }
  if (best == kInf) return false;
  hit.hit = true;
  hit.range_m = best;
  hit.point_m = o + best * d;
  hit.normal = normal;
  hit.kind = RayHit::Kind::kPole;
  hit.cls = pole.cls;
  hit.lidar_intensity = pole.lidar_intensity;
  hit.rgb = pole.rgb;
  return true;
}

// Amanatides–Woo traversal of the 2-D grid; stops at the first cell whose exit lies beyond
// the best hit so far.
RayHit SceneRaycaster::cast_objects(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                                    double t_max) const {
  RayHit best;
  if (objects_.empty()) return best;
  // Clip to the grid rectangle.
  const double gx1 = grid_x0_ + grid_nx_ * cell_m_, gy1 = grid_y0_ + grid_ny_ * cell_m_;
  double t0 = t_min, t1 = t_max;
  const double lo[2] = {grid_x0_, grid_y0_}, hi[2] = {gx1, gy1};
  for (int a = 0; a < 2; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < lo[a] || o[a] > hi[a]) return best;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return best;
  // Objects lie between objects_z_min_ and objects_z_max_: shorten the walk to that slab.
  if (d.z() > 0.0) {
    if (o.z() + t0 * d.z() > objects_z_max_) return best;
    t1 = std::min(t1, (objects_z_max_ - o.z()) / d.z());
  } else if (d.z() < 0.0) {
    if (o.z() + t0 * d.z() < objects_z_min_) return best;
    t1 = std::min(t1, (objects_z_min_ - o.z()) / d.z());
  }
  if (t0 > t1) return best;

  const double sx = o.x() + t0 * d.x(), sy = o.y() + t0 * d.y();
  int ix = std::clamp(static_cast<int>(std::floor((sx - grid_x0_) / cell_m_)), 0, grid_nx_ - 1);
  int iy = std::clamp(static_cast<int>(std::floor((sy - grid_y0_) / cell_m_)), 0, grid_ny_ - 1);
  const int step_x = d.x() > 0 ? 1 : -1, step_y = d.y() > 0 ? 1 : -1;
  const double inv_dx = std::abs(d.x()) > 1e-15 ? 1.0 / d.x() : kInf;
  const double inv_dy = std::abs(d.y()) > 1e-15 ? 1.0 / d.y() : kInf;
  auto next_boundary = [&](int i, int step, double origin, double x0, double inv) {
    if (inv == kInf) return kInf;
    const double edge = x0 + (step > 0 ? i + 1 : i) * cell_m_;
    return (edge - origin) * inv;
  };
  double t_next_x = next_boundary(ix, step_x, o.x(), grid_x0_, inv_dx);
  double t_next_y = next_boundary(iy, step_y, o.y(), grid_y0_, inv_dy);
  const double dt_x = inv_dx == kInf ? kInf : cell_m_ * std::abs(inv_dx);
  const double dt_y = inv_dy == kInf ? kInf : cell_m_ * std::abs(inv_dy);

  double t_cell_in = t0;
  double limit = t1;
  while (true) {
    const double t_cell_out = std::min({t_next_x, t_next_y, t1});
    const double z_a = o.z() + t_cell_in * d.z(), z_b = o.z() + t_cell_out * d.z();
    const double z_lo = std::min(z_a, z_b), z_hi = std::max(z_a, z_b);
    const size_t c = static_cast<size_t>(iy) * grid_nx_ + ix;
    for (uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
      const Object& obj = objects_[cell_items_[k]];
      if (obj.z_max < z_lo || obj.z_min > z_hi) continue;
      RayHit h;
      if (intersect(obj, o, d, t_min, limit, h) && h.range_m < limit) {
        best = h;
        limit = h.range_m;
      }
    }
    if (best.hit && best.range_m <= t_cell_out) break;
    if (t_cell_out >= t1) break;
    if (t_next_x < t_next_y) {
      ix += step_x;
      t_cell_in = t_next_x;
      t_next_x += dt_x;
      if (ix < 0 || ix >= grid_nx_) break;
    } else {
      iy += step_y;
      t_cell_in = t_next_y;
      t_next_y += dt_y;
      if (iy < 0 || iy >= grid_ny_) break;
    }
  }
  return best;
}

RayHit SceneRaycaster::cast_ground(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_range_m) const {
  RayHit miss;
  const double g_lo = options_.ground_min_height_m, g_hi = options_.ground_max_height_m;
  const double dz = d.z();
  // The part of the ray inside the height band [g_lo, g_hi].
  double t0 = 0.0, t1 = max_range_m;
  if (o.z() > g_hi) {
    if (dz >= 0.0) return miss;
    t0 = (o.z() - g_hi) / -dz;
  } else if (o.z() < g_lo) {
    return miss;  // below the ground band: nothing to see
  }
  if (dz < 0.0) t1 = std::min(t1, (o.z() - g_lo) / -dz);
  if (!clip_to_bounds(o, d, t0, t1)) return miss;
  if (t0 > t1) return miss;

  const auto at = [&](double t) { return scene_.ground(o.x() + t * d.x(), o.y() + t * d.y()); };
  const auto below = [&](double t, const GroundSample& s) { return o.z() + t * d.z() <= s.height_m; };
  auto make_hit = [&](double t, const GroundSample& s, const Eigen::Vector3d& normal) {
    RayHit h;
    h.hit = true;
    h.range_m = t;
    h.point_m = o + t * d;
    h.normal = normal;
    h.kind = RayHit::Kind::kGround;
    h.material = s.material;
    h.cls = ground_class(s.material);
    return h;
  };

  const double dxy = std::hypot(d.x(), d.y());
  double dt = dz < 0.0 ? options_.max_drop_per_step_m / -dz : kInf;
  if (dxy > 1e-12) {
    dt = std::min(dt, options_.max_step_m / dxy);
    dt = std::max(dt, options_.min_step_m / dxy);
  }
  if (!(dt < kInf)) dt = std::max(t1 - t0, 1e-3);
  dt = std::max(dt, (t1 - t0) / 200000.0);  // bounded work per ray

  GroundSample s_prev = at(t0);
  if (below(t0, s_prev)) return make_hit(t0, s_prev, Eigen::Vector3d::UnitZ());
  double a = t0;
  while (a < t1) {
    const double b = std::min(a + dt, t1);
    GroundSample s_b = at(b);
    if (below(b, s_b)) {
      // Refine in (a, b]: first try the plane of the sample's height; else bisect.
      double lo = a, hi = b;
      for (int iter = 0; iter < 16; ++iter) {
        if (dz < 0.0) {
          const double t_plane = (o.z() - s_b.height_m) / -dz;
          if (t_plane >= lo && t_plane <= hi) {
            const GroundSample s_p = at(t_plane);
            if (s_p.height_m == s_b.height_m) return make_hit(t_plane, s_p, Eigen::Vector3d::UnitZ());
          }
        }
        const double mid = 0.5 * (lo + hi);
        const GroundSample s_m = at(mid);
        if (below(mid, s_m)) {
          hi = mid;
          s_b = s_m;
        } else {
          lo = mid;
        }
      }
      // A vertical step (curb face) between lo and hi.
      Eigen::Vector3d n(-d.x(), -d.y(), 0.0);
      n = n.norm() > 1e-12 ? n.normalized() : Eigen::Vector3d::UnitZ();
      return make_hit(hi, s_b, n);
    }
    a = b;
  }
  return miss;
}

RayHit SceneRaycaster::cast(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& direction, double max_range_m,
                            double min_range_m) const {
  RayHit none;
  const double norm = direction.norm();
  if (!(norm > 0.0) || !finite(norm)) return none;
  const Eigen::Vector3d d = direction / norm;
  double t_min = min_range_m, t_max = max_range_m;
  if (!clip_to_bounds(origin_m, d, t_min, t_max)) return none;
  RayHit obj = cast_objects(origin_m, d, t_min, t_max);
  const double ground_limit = obj.hit ? obj.range_m : t_max;
  RayHit ground = cast_ground(origin_m, d, ground_limit);
  if (ground.hit && ground.range_m > min_range_m && (!obj.hit || ground.range_m < obj.range_m)) {
    return ground;
  }
  return obj;
}

// ---------------------------------------------------------------------------------------
// LiDAR

double lidar_ground_intensity(GroundMaterial material) {
  switch (material) {
    case GroundMaterial::kAsphalt: return 10.0;
    case GroundMaterial::kPaintWhite: return 95.0;
    case GroundMaterial::kPaintYellow: return 85.0;
    case GroundMaterial::kCrosswalkPaint: return 100.0;
    case GroundMaterial::kSidewalk: return 30.0;
    case GroundMaterial::kCurbTop: return 38.0;
    case GroundMaterial::kTerrain: return 20.0;
    case GroundMaterial::kVegetation: return 26.0;
  }
  return 20.0;
}

namespace {

// Noise half-width of the intensity of a ground return: asphalt stays in 5..15, paint in
// 70..110, so a threshold near 50 separates them.
double ground_intensity_spread(GroundMaterial material) {
  switch (material) {
    case GroundMaterial::kAsphalt: return 5.0;
    case GroundMaterial::kPaintWhite:
    case GroundMaterial::kPaintYellow:
    case GroundMaterial::kCrosswalkPaint: return 15.0;
    default: return 8.0;
  }
}

float quantise_intensity(double value) { return static_cast<float>(std::clamp(std::round(value), 0.0, 255.0)); }

}  // namespace

std::vector<float> simulate_lidar_sweep(const SceneSnapshot& scene, const geometry::Rigid3& global_from_sensor,
                                        const LidarSimOptions& options, Rng& rng) {
  options.validate();
  const SceneRaycaster caster(scene, options.raycast);
  return simulate_lidar_sweep(caster, global_from_sensor, options, rng);
}

uint8_t lidarseg_label(const RayHit& hit) {
  if (!hit.hit) return 0;  // noise
  if (hit.kind == RayHit::Kind::kGround) {
    switch (hit.material) {
      case GroundMaterial::kAsphalt:
      case GroundMaterial::kPaintWhite:
      case GroundMaterial::kPaintYellow:
      case GroundMaterial::kCrosswalkPaint: return 24;  // flat.driveable_surface
      case GroundMaterial::kSidewalk:
      case GroundMaterial::kCurbTop: return 26;     // flat.sidewalk
      case GroundMaterial::kTerrain: return 27;     // flat.terrain
      case GroundMaterial::kVegetation: return 30;  // static.vegetation
    }
    return 25;  // flat.other
  }
  switch (hit.cls) {
    case SemanticClass::kCar: return 17;         // vehicle.car
    case SemanticClass::kTruckBus: return 23;    // vehicle.truck (buses too: one class of ours)
    case SemanticClass::kPerson: return 2;       // human.pedestrian.adult
    case SemanticClass::kTwoWheeler: return 14;  // vehicle.bicycle
    case SemanticClass::kBuilding:
    case SemanticClass::kPoleSign: return 28;    // static.manmade
    case SemanticClass::kVegetation: return 30;  // static.vegetation (tree trunks)
    default: return 29;                          // static.other
  }
}

std::vector<float> simulate_lidar_sweep(const SceneRaycaster& caster, const geometry::Rigid3& global_from_sensor,
                                        const LidarSimOptions& options, Rng& rng,
                                        std::vector<uint8_t>* lidarseg_labels) {
  options.validate();
  if (lidarseg_labels != nullptr) lidarseg_labels->clear();
  const int beams = options.beams;
  const int azimuth_steps = options.points_per_sweep / beams;
  std::vector<double> cos_el(beams), sin_el(beams);
  for (int r = 0; r < beams; ++r) {
    const double el_deg = beams == 1 ? options.elevation_min_deg
                                     : options.elevation_min_deg +
                                           (options.elevation_max_deg - options.elevation_min_deg) * r / (beams - 1);
    cos_el[r] = std::cos(el_deg * kPi / 180.0);
    sin_el[r] = std::sin(el_deg * kPi / 180.0);
  }
  const Eigen::Vector3d origin = global_from_sensor.translation;
  const Eigen::Matrix3d& rotation = global_from_sensor.rotation;
  constexpr double kRoofHalf = 0.98;  // roof returns stay strictly inside |x|,|y| < 1

  std::vector<float> out;
  out.reserve(static_cast<size_t>(azimuth_steps) * beams * 5);
  for (int k = 0; k < azimuth_steps; ++k) {
    const double az = 2.0 * kPi * k / azimuth_steps;  // clockwise from +y towards +x
    const double sa = std::sin(az), ca = std::cos(az);
    for (int r = 0; r < beams; ++r) {
      const Eigen::Vector3d dir(cos_el[r] * sa, cos_el[r] * ca, sin_el[r]);
      const bool roof = static_cast<long>(r) * azimuth_steps + k < options.roof_points;
      double range = 0.0, intensity = 0.0;
      uint8_t label = kLidarsegEgo;
      if (roof) {
        // The roof plane z = −roof_depth_m, or the edge of the roof square if the ray
        // leaves it first.
        const double t_edge = kRoofHalf / std::max({std::abs(dir.x()), std::abs(dir.y()), 1e-9});
        const double t_plane = dir.z() < 0.0 ? options.roof_depth_m / -dir.z() : kInf;
        range = std::min(t_edge, t_plane);
        intensity = 4.0 + rng.uniform(0.0, 10.0);
        range += options.range_noise_m * rng.normal();
        range = std::min(range, t_edge);
        range = std::max(range, 0.05);
      } else {
        const RayHit hit = caster.cast(origin, rotation * dir, options.max_range_m);
        if (!hit.hit) continue;
        label = lidarseg_label(hit);
        if (hit.kind == RayHit::Kind::kGround) {
          const double spread = ground_intensity_spread(hit.material);
          intensity = lidar_ground_intensity(hit.material) + rng.uniform(-spread, spread);
        } else {
          const double base = hit.lidar_intensity;
          const double spread = std::max(2.0, 0.15 * base);
          intensity = base + rng.uniform(-spread, spread);
        }
        range = hit.range_m + options.range_noise_m * rng.normal();
        range = std::max(range, 0.0);
      }
      const Eigen::Vector3d p = dir * range;
      out.push_back(static_cast<float>(p.x()));
      out.push_back(static_cast<float>(p.y()));
      out.push_back(static_cast<float>(p.z()));
      out.push_back(quantise_intensity(intensity));
      out.push_back(static_cast<float>(r));
      if (lidarseg_labels != nullptr) lidarseg_labels->push_back(label);
    }
  }
  return out;
}

}  // namespace nsg::synth
