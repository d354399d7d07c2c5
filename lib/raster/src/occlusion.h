// The camera stage's view of one image and its occlusion test: the pinhole projection
// of a camera, the key-frame sweep the test uses and the shadow buffer it builds.
// Internal to the raster module (color_layer.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/raster/color_layer.h"

namespace nsg::raster::detail {

using nuscenes::Database;
using nuscenes::Index;

constexpr int kShadowCellPx = 4;  // occlusion buffer cell (full-resolution pixels)

// A key-frame sweep as the occlusion test uses it, read, stripped of the ego's roof
// returns (devkit remove_close: not obstacles) and moved to the global frame once for all
// the cameras of its key frame (six on nuScenes).
struct OcclusionSweep {
  // Consecutive points in file order: a spinning LiDAR writes them column by column, so
  // a run is a narrow wedge of azimuth, and a camera skips the runs outside its view.
  static constexpr size_t kRunPoints = 512;
  struct Run {
    float lo[3], hi[3];  // bounds of the run's global x, y, z
  };
  std::vector<nuscenes::LidarPoint> points;  // global frame, roof returns removed
  std::vector<Run> runs;                     // run k: points [k·kRunPoints, (k + 1)·kRunPoints)
  size_t rows_read = 0;                      // the file's rows, before the roof filter
  float max_ring = 0.0f;                     // the largest ring index read
};

// Into `sweep`, whose buffer is reused.
void load_occlusion_sweep(const Database& db, Index lidar, OcclusionSweep& sweep);

// Pinhole projection of one image: camera_from_global and K, as the devkit chain does.
struct ViewGeometry {
  geometry::Rigid3 camera_from_global;
  Eigen::Matrix3d k;
  int width = 0, height = 0;
  double ego_x = 0.0, ego_y = 0.0;

  // Depth and pixel of a global point; false when behind the camera plane, or when its
  // depth is not above min_depth_m (then u, v are not computed: most of a sweep lies
  // behind any one camera, and the callers drop those points either way).
  bool project(double x, double y, double z, double min_depth_m, double& depth, double& u, double& v) const {
    const Eigen::Vector3d p = camera_from_global.apply(Eigen::Vector3d(x, y, z));
    depth = p.z();
    if (!(depth > min_depth_m)) return false;
    const Eigen::Vector3d q = k * p;
    if (!(q.z() > 0.0)) return false;
    u = q.x() / q.z();
    v = q.y() / q.z();
    return true;
  }
  bool inside(double u, double v) const { return u > 1.0 && u < width - 1.0 && v > 1.0 && v < height - 1.0; }

  // True when no point of the box [lo, hi] can pass project(min_depth_m) with its pixel
  // inside the window u0 < u < u1, v0 < v < v1 (±inf: no bound): the box lies wholly
  // outside one of the half-spaces depth > min_depth_m, u > u0, … (linear forms of the
  // global point, which any point projecting into the window satisfies). Culls only with a
  // margin far above the rounding of project(), so it never drops a point project() keeps.
  bool misses_box(const float lo[3], const float hi[3], double min_depth_m, double u0, double u1, double v0,
                  double v1) const {
    const Eigen::Matrix3d& r = camera_from_global.rotation;
    const Eigen::Vector3d& t = camera_from_global.translation;
    const Eigen::Matrix3d kr = k * r;
    const Eigen::Vector3d kt = k * t;
    constexpr double kMargin = 1e-3;  // m for the depth form, px·m for the others
    // Whether a·g + b < −margin at every corner of the box (its largest value is).
    const auto below = [&](const Eigen::RowVector3d& a, double b) {
      double most = b;
      for (int i = 0; i < 3; ++i) most += std::max(a(i) * lo[i], a(i) * hi[i]);
      return most < -kMargin;
    };
    // u > u0 ⇔ q.x − u0·q.z > 0 (q.z > 0 for a projected point); u < u1 ⇔ u1·q.z − q.x > 0.
    const auto above_bound = [&](int axis, double bound) {
      return std::isfinite(bound) && below(kr.row(axis) - bound * kr.row(2), kt(axis) - bound * kt.z());
    };
    const auto below_bound = [&](int axis, double bound) {
      return std::isfinite(bound) && below(bound * kr.row(2) - kr.row(axis), bound * kt.z() - kt(axis));
    };
    return below(r.row(2), t.z() - min_depth_m) || above_bound(0, u0) || below_bound(0, u1) || above_bound(1, v0) ||
           below_bound(1, v1);
  }
};

ViewGeometry view_geometry(const Database& db, Index camera);

// The occlusion test as a depth buffer looked up at the point's own pixel. Each LiDAR
// return Q of the key frame casts a "shadow": the image rectangle it may hide, ± side_px
// sideways, from the row where the line of sight passes height_m below Q down to window_px
// further. A point P is occluded when a shadow covering its pixel comes from a return
// closer by more than margin_m. Why this shape: flat ground in front of P lies below P's
// line of sight (up to the few cm by which the kept lowest-z point sits below the surface),
// so it never casts a shadow over P, however dense the rings at a grazing angle; an object
// standing between the camera and P rises above that line and, as rings sample it every
// ≈ 29 px, has a return within window_px above P. Cells are kShadowCellPx² and a return
// writes only the cells its rectangle covers entirely, so a shadow never grows.
class ShadowBuffer {
 public:
  // `storage`: the cells' memory, kept between images by the caller (a fresh buffer per
  // image cost more in page faults than the shadows themselves).
  ShadowBuffer(const ViewGeometry& view, const CameraOptions& options, std::vector<float>& storage)
      : cols_(view.width / kShadowCellPx + 1),
        rows_(view.height / kShadowCellPx + 1),
        side_px_(options.occlusion_side_px),
        window_px_(options.occlusion_window_px),
        height_px_m_(view.k(1, 1) * options.occlusion_height_m),
        depth_(storage) {
    depth_.assign(static_cast<size_t>(cols_) * rows_, std::numeric_limits<float>::infinity());
  }

  void add_sweep(const OcclusionSweep& sweep, const ViewGeometry& view) {
    if (side_px_ == 0.0) side_px_ = column_spacing_px(sweep, view);
    // A return casts only from u ∈ (−side, width + side) and v below the buffer's bottom
    // (its shadow starts below v), so runs of the sweep outside that window are skipped;
    // the shadows are minima, the same in any order.
    const double u0 = -side_px_, u1 = cols_ * kShadowCellPx + side_px_, v1 = rows_ * kShadowCellPx;
    const double inf = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < sweep.runs.size(); ++k) {
      const OcclusionSweep::Run& run = sweep.runs[k];
      if (view.misses_box(run.lo, run.hi, 0.0, u0, u1, -inf, v1)) continue;
      const size_t first = k * OcclusionSweep::kRunPoints;
      const size_t last = std::min(sweep.points.size(), first + OcclusionSweep::kRunPoints);
      for (size_t i = first; i < last; ++i) {
        const nuscenes::LidarPoint& p = sweep.points[i];
        double depth, u, v;
        if (!view.project(p.x, p.y, p.z, 0.0, depth, u, v)) continue;
        cast(u, v + height_px_m_ / depth, static_cast<float>(depth));
      }
    }
  }
  // Depth of the closest return whose shadow covers pixel (u, v); +inf when none does.
  float closest(double u, double v) const {
    const int c = static_cast<int>(std::floor(u / kShadowCellPx)), r = static_cast<int>(std::floor(v / kShadowCellPx));
    if (c < 0 || r < 0 || c >= cols_ || r >= rows_) return std::numeric_limits<float>::infinity();
    return depth_[static_cast<size_t>(r) * cols_ + c];
  }

 private:
  // The image width of one step between the sweep's columns (a spinning LiDAR returns
  // rings × columns points; 2π / columns in azimuth, f_x px per radian): a shadow as wide
  // closes the gaps between columns on an object, and no wider, so a raised kerb or a
  // pole beside a point does not hide it. Rings = the largest ring index + 1; a sweep
  // without plausible ring indices counts as 32 beams (the nuScenes HDL-32E).
  static double column_spacing_px(const OcclusionSweep& sweep, const ViewGeometry& view) {
    const float max_ring = sweep.max_ring;
    const double rings = max_ring >= 1.0f && max_ring < 128.0f ? std::floor(max_ring) + 1.0 : 32.0;
    const double columns = std::max(1.0, static_cast<double>(sweep.rows_read) / rings);
    return std::min(512.0, view.k(0, 0) * 2.0 * std::numbers::pi / columns);
  }

  // Cells entirely inside [u − side, u + side] × [top, top + window].
  void cast(double u, double top, float depth) {
    const double u0 = u - side_px_, u1 = u + side_px_, v1 = top + window_px_;
    if (!(u1 > 0.0) || !(v1 > 0.0) || !(u0 < cols_ * kShadowCellPx) || !(top < rows_ * kShadowCellPx)) return;
    const int c0 = std::max(0, static_cast<int>(std::ceil(u0 / kShadowCellPx)));
    const int c1 = std::min(cols_, static_cast<int>(std::floor(u1 / kShadowCellPx)));  // exclusive
    const int r0 = std::max(0, static_cast<int>(std::ceil(top / kShadowCellPx)));
    const int r1 = std::min(rows_, static_cast<int>(std::floor(v1 / kShadowCellPx)));
    for (int r = r0; r < r1; ++r) {
      float* row = depth_.data() + static_cast<size_t>(r) * cols_;
      for (int c = c0; c < c1; ++c) row[c] = std::min(row[c], depth);
    }
  }

  int cols_, rows_;
  double side_px_, window_px_, height_px_m_;  // height_px_m_: focal length (px) × occlusion_height_m
  std::vector<float>& depth_;
};

// The key-frame sweeps of the images in flight: each read once for the cameras of its key
// frame, also when they fall into two chunks (the sweeps of the previous chunk are kept
// for the next). At most one sweep per image of a chunk (≈ 0.7 MB each) is held, in slots
// whose buffers are reused.
class SweepCache {
 public:
  // Holds the sweeps `needed` (kNoIndex entries ignored), reading those not yet held.
  void load(const Database& db, std::vector<Index> needed, int threads);
  const OcclusionSweep* find(Index lidar) const;

 private:
  struct Slot {
    Index lidar = nuscenes::kNoIndex;
    OcclusionSweep sweep;
  };
  std::deque<Slot> slots_;  // a deque: slots keep their address as it grows
};

}  // namespace nsg::raster::detail
