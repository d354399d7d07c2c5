#include "nsg/model/anchors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "nsg/core/error.h"
#include "nsg/model/direction.h"

namespace nsg::model {

float anchor_target(const metrics::Graph& truth, double u, double v, double sigma_px) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& n : truth.nodes) best = std::min(best, (n.u - u) * (n.u - u) + (n.v - v) * (n.v - v));
  if (!std::isfinite(best)) return 0.0f;
  return static_cast<float>(std::exp(-0.5 * best / (sigma_px * sigma_px)));
}

std::vector<std::array<double, 2>> detect_anchors(const cv::Mat& score, const AnchorOptions& options) {
  options.validate();
  NSG_CHECK(score.type() == CV_32F, DataError, "", "anchor score", "a CV_32F map");
  // A fresh output: GaussianBlur into a header sharing the input's pixels would blur the
  // caller's map in place.
  cv::Mat s;
  if (options.smooth_sigma_px > 0.0) cv::GaussianBlur(score, s, {0, 0}, options.smooth_sigma_px);
  else s = score;
  const int rows = s.rows, cols = s.cols;
  auto at = [&](int v, int u) { return u < 0 || v < 0 || u >= cols || v >= rows ? -1.0f : s.at<float>(v, u); };
  // Ridge test: across a lane the score falls on both sides; along it, it may not. A
  // pixel on a slope beside the ridge is a maximum along at most one axis.
  static const int kAxes[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  std::vector<int> candidates;
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      const float c = s.at<float>(v, u);
      if (c < options.min_score) continue;
      int maxima = 0;
      for (const auto& a : kAxes) maxima += c >= at(v + a[1], u + a[0]) && c >= at(v - a[1], u - a[0]);
      if (maxima >= 2) candidates.push_back(v * cols + u);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [&](int a, int b) {
    return reinterpret_cast<const float*>(s.data)[a] > reinterpret_cast<const float*>(s.data)[b];
  });
  // Greedy suppression on a coarse grid of kept anchors (cells of the radius's size).
  const double r2 = options.nms_radius_px * options.nms_radius_px;
  const int cell = std::max(1, static_cast<int>(std::ceil(options.nms_radius_px)));
  const int gw = (cols + cell - 1) / cell, gh = (rows + cell - 1) / cell;
  std::vector<std::vector<int>> grid(static_cast<size_t>(gw * gh));
  std::vector<std::array<double, 2>> kept;
  for (int i : candidates) {
    const int u = i % cols, v = i / cols, gu = u / cell, gv = v / cell;
    bool free = true;
    for (int y = std::max(0, gv - 1); y <= std::min(gh - 1, gv + 1) && free; ++y) {
      for (int x = std::max(0, gu - 1); x <= std::min(gw - 1, gu + 1) && free; ++x) {
        for (int k : grid[static_cast<size_t>(y * gw + x)]) {
          const double du = kept[static_cast<size_t>(k)][0] - u, dv = kept[static_cast<size_t>(k)][1] - v;
          if (du * du + dv * dv < r2) {
            free = false;
            break;
          }
        }
      }
    }
    if (!free) continue;
    grid[static_cast<size_t>(gv * gw + gu)].push_back(static_cast<int>(kept.size()));
    kept.push_back({static_cast<double>(u), static_cast<double>(v)});
  }
  return kept;
}

std::vector<std::array<int, 2>> nearest_neighbour_pairs(const std::vector<std::array<double, 2>>& anchors, int k) {
  std::vector<std::array<int, 2>> pairs;
  const int n = static_cast<int>(anchors.size());
  for (int i = 0; i < n; ++i) {
    std::vector<std::pair<double, int>> by_distance;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      const double du = anchors[j][0] - anchors[i][0], dv = anchors[j][1] - anchors[i][1];
      by_distance.emplace_back(du * du + dv * dv, j);
    }
    const size_t take = std::min(by_distance.size(), static_cast<size_t>(k));
    std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(take), by_distance.end());
    for (size_t m = 0; m < take; ++m) {
      const int j = by_distance[m].second;
      pairs.push_back({std::min(i, j), std::max(i, j)});
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

AnchorSet make_anchor_set(const cv::Mat& score, const DirectionVotes& votes, const AnchorOptions& options) {
  AnchorSet a;
  a.points = detect_anchors(score, options);
  a.votes = a.points.empty() ? std::vector<Votes>{} : votes(a.points);
  NSG_CHECK(a.votes.size() == a.points.size(), DataError, "", "direction votes", "one per anchor");
  for (size_t i = 0; i < a.points.size(); ++i) {
    a.scores.push_back(sample_bilinear(score, a.points[i][0], a.points[i][1]));
    a.mean_dir.push_back(mean_direction_px(a.votes[i]));
  }
  return a;
}

}  // namespace nsg::model
