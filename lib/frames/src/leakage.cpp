// Nearest train frame per test frame: train positions sorted by x, searched outwards from
// the test frame's x until the x gap alone exceeds the best distance (exact, no grid).
// Window leakage: train windows bucketed by map cell, each test window sampled on a grid.
#include "nsg/frames/leakage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace nsg::frames {
namespace {

struct Point {
  double x, y;
};

double nearest_distance(const std::vector<Point>& sorted_by_x, const Point& p) {
  const auto first =
      std::lower_bound(sorted_by_x.begin(), sorted_by_x.end(), p.x, [](const Point& a, double x) { return a.x < x; });
  double best2 = std::numeric_limits<double>::infinity();
  const auto consider = [&](const Point& q) {
    const double dx = q.x - p.x, dy = q.y - p.y;
    best2 = std::min(best2, dx * dx + dy * dy);
  };
  for (auto it = first; it != sorted_by_x.end(); ++it) {
    const double dx = it->x - p.x;
    if (dx * dx > best2) break;
    consider(*it);
  }
  for (auto it = first; it != sorted_by_x.begin();) {
    --it;
    const double dx = p.x - it->x;
    if (dx * dx > best2) break;
    consider(*it);
  }
  return std::sqrt(best2);
}

// The window's farthest corner from the ego.
double reach_m(const WindowM& w) {
  return std::max({std::hypot(w.x_min_m, w.y_min_m), std::hypot(w.x_min_m, w.y_max_m), std::hypot(w.x_max_m, w.y_min_m),
                   std::hypot(w.x_max_m, w.y_max_m)});
}

// A frame's window as a rectangle in the map: a point is inside when, turned into the
// frame's ego axes, it lies within the window's edges.
struct PlacedWindow {
  double x, y, cos_yaw, sin_yaw;
  bool contains(double px, double py, const WindowM& w) const {
    const double dx = px - x, dy = py - y;
    const double u = cos_yaw * dx + sin_yaw * dy;
    const double v = -sin_yaw * dx + cos_yaw * dy;
    return u >= w.x_min_m && u <= w.x_max_m && v >= w.y_min_m && v <= w.y_max_m;
  }
};

// The train windows of one location, bucketed by the 50 m map cells their bounding boxes
// touch, so a point is tested only against the windows that can contain it.
class TrainWindows {
 public:
  static constexpr double kBucketM = 50.0;

  explicit TrainWindows(const WindowM& window) : window_(window), reach_m_(reach_m(window)) {}

  void add(const EgoPosition& f) {
    const size_t index = windows_.size();
    windows_.push_back({f.x_m, f.y_m, std::cos(f.yaw_rad), std::sin(f.yaw_rad)});
    for (int64_t bx = bucket(f.x_m - reach_m_); bx <= bucket(f.x_m + reach_m_); ++bx)
      for (int64_t by = bucket(f.y_m - reach_m_); by <= bucket(f.y_m + reach_m_); ++by)
        buckets_[{bx, by}].push_back(index);
  }

  bool covers(double px, double py) const {
    const auto it = buckets_.find({bucket(px), bucket(py)});
    if (it == buckets_.end()) return false;
    for (const size_t i : it->second)
      if (windows_[i].contains(px, py, window_)) return true;
    return false;
  }

 private:
  static int64_t bucket(double v) { return static_cast<int64_t>(std::floor(v / kBucketM)); }

  WindowM window_;
  double reach_m_;  // the window's farthest corner from the ego
  std::vector<PlacedWindow> windows_;
  std::map<std::pair<int64_t, int64_t>, std::vector<size_t>> buckets_;
};

}  // namespace

std::vector<LeakageBand> window_leakage(const std::vector<EgoPosition>& frames, const WindowM& window) {
  std::vector<LeakageBand> bands;
  for (double from = 0.0; from < reach_m(window); from += kLeakageBandM)
    bands.push_back({from, from + kLeakageBandM, 0, 0});
  std::map<std::string, TrainWindows> train;
  for (const EgoPosition& f : frames)
    if (f.split == 0) train.try_emplace(f.location, window).first->second.add(f);
  const int cells_u = static_cast<int>(std::floor((window.x_max_m - window.x_min_m) / kLeakageCellM));
  const int cells_v = static_cast<int>(std::floor((window.y_max_m - window.y_min_m) / kLeakageCellM));
  for (const EgoPosition& f : frames) {
    if (f.split != 2) continue;
    const auto it = train.find(f.location);
    const double c = std::cos(f.yaw_rad), s = std::sin(f.yaw_rad);
    for (int i = 0; i < cells_u; ++i)
      for (int j = 0; j < cells_v; ++j) {
        const double u = window.x_min_m + (i + 0.5) * kLeakageCellM;
        const double v = window.y_min_m + (j + 0.5) * kLeakageCellM;
        LeakageBand& band = bands[std::min(bands.size() - 1, static_cast<size_t>(std::hypot(u, v) / kLeakageBandM))];
        ++band.window_cells;
        if (it != train.end() && it->second.covers(f.x_m + c * u - s * v, f.y_m + s * u + c * v)) ++band.seen_cells;
      }
  }
  return bands;
}

Leakage measure_leakage(const std::vector<EgoPosition>& frames, double radius_m, const WindowM& window) {
  std::map<std::string, std::vector<Point>> train;  // per location, sorted by x
  for (const EgoPosition& f : frames)
    if (f.split == 0) train[f.location].push_back({f.x_m, f.y_m});
  Leakage out;
  for (auto& [location, points] : train) {
    std::sort(points.begin(), points.end(), [](const Point& a, const Point& b) { return a.x < b.x; });
    out.train_frames += static_cast<int64_t>(points.size());
  }
  std::vector<double> distances;
  for (const EgoPosition& f : frames) {
    if (f.split != 2) continue;
    ++out.test_frames;
    const auto it = train.find(f.location);
    if (it == train.end()) continue;  // no train frame in this location: nothing to leak from
    const double d = nearest_distance(it->second, {f.x_m, f.y_m});
    distances.push_back(d);
    if (d < radius_m) ++out.test_within_radius;
  }
  if (out.test_frames > 0) out.share_within = static_cast<double>(out.test_within_radius) / out.test_frames;
  if (!distances.empty()) {
    std::sort(distances.begin(), distances.end());
    const size_t n = distances.size();
    out.median_distance_m = n % 2 ? distances[n / 2] : 0.5 * (distances[n / 2 - 1] + distances[n / 2]);
  }
  out.by_distance = window_leakage(frames, window);
  return out;
}

}  // namespace nsg::frames
