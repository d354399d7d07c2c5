// Nearest train frame per test frame: train positions sorted by x, searched outwards from
// the test frame's x until the x gap alone exceeds the best distance (exact, no grid).
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

}  // namespace

Leakage measure_leakage(const std::vector<EgoPosition>& frames, double radius_m) {
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
  return out;
}

}  // namespace nsg::frames
