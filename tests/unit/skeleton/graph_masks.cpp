#include "graph_masks.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "nsg/core/rng.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/params.h"

namespace nsg::test {
namespace {

// Appends a polyline as nodes and one-way edges; `join` (≥ 0) is an existing node to
// start from (a split or a crossing shares it).
void add_polyline(metrics::Graph& g, const std::vector<cv::Point2d>& pts, int64_t join = -1) {
  int64_t prev = join;
  for (size_t k = 0; k < pts.size(); ++k) {
    if (k == 0 && join >= 0) continue;
    const auto id = static_cast<int64_t>(g.nodes.size());
    g.nodes.push_back({pts[k].x, pts[k].y});
    if (prev >= 0) g.edges.push_back({prev, id});
    prev = id;
  }
}

}  // namespace

std::vector<cv::Point2d> line(cv::Point2d a, cv::Point2d b, int pieces) {
  std::vector<cv::Point2d> pts;
  for (int s = 0; s <= pieces; ++s) pts.push_back(a + (b - a) * (static_cast<double>(s) / pieces));
  return pts;
}

void add_line(metrics::Graph& g, cv::Point2d a, cv::Point2d b, int pieces) { add_polyline(g, line(a, b, pieces)); }

std::vector<GraphCase> graph_cases() {
  std::vector<GraphCase> cases;
  GraphCase straight{"straight", {}};
  add_polyline(straight.truth, line({16, 128}, {240, 128}, 8));
  cases.push_back(straight);

  GraphCase curve{"curve", {}};
  std::vector<cv::Point2d> arc;
  for (int s = 0; s <= 24; ++s) {
    const double t = (M_PI / 2) * s / 24.0;  // a quarter circle of radius 180 px
    arc.push_back({30 + 180 * std::sin(t), 226 - 180 * (1 - std::cos(t))});
  }
  add_polyline(curve.truth, arc);
  cases.push_back(curve);

  GraphCase split{"y_split", {}};
  add_polyline(split.truth, line({128, 240}, {128, 128}, 4));
  const int64_t fork = static_cast<int64_t>(split.truth.nodes.size()) - 1;
  add_polyline(split.truth, line({128, 128}, {48, 20}, 4), fork);
  add_polyline(split.truth, line({128, 128}, {208, 20}, 4), fork);
  cases.push_back(split);

  GraphCase parallel{"parallel_3.5m", {}};
  add_polyline(parallel.truth, line({16, 119.25}, {240, 119.25}, 8));
  add_polyline(parallel.truth, line({240, 136.75}, {16, 136.75}, 8));
  cases.push_back(parallel);

  // Two lanes crossing share no node (a lane graph's crossing, as a dataset tile's); no node
  // at the crossing point, where APLS could snap it onto either line.
  GraphCase crossing{"crossing", {}};
  add_polyline(crossing.truth, line({16, 128}, {240, 128}, 7));
  add_polyline(crossing.truth, line({128, 16}, {128, 240}, 7));
  cases.push_back(crossing);
  return cases;
}

cv::Mat draw_mask(const metrics::Graph& truth, int width_px, int size_px) {
  cv::Mat mask = cv::Mat::zeros(size_px, size_px, CV_8U);
  for (const auto& e : truth.edges) {
    const auto& a = truth.nodes[static_cast<size_t>(e[0])];
    const auto& b = truth.nodes[static_cast<size_t>(e[1])];
    // Sub-pixel endpoints (4 fractional bits), so the 17.5-px spacing is drawn as it is.
    cv::line(mask, {static_cast<int>(std::lround(a.u * 16)), static_cast<int>(std::lround(a.v * 16))},
             {static_cast<int>(std::lround(b.u * 16)), static_cast<int>(std::lround(b.v * 16))}, cv::Scalar(255),
             width_px, cv::LINE_8, 4);
  }
  return mask;
}

cv::Mat draw_heading(const metrics::Graph& truth, int width_px, int size_px) {
  cv::Mat heading(size_px, size_px, CV_32F, cv::Scalar(-1.0f));
  for (const auto& e : truth.edges) {
    const auto& a = truth.nodes[static_cast<size_t>(e[0])];
    const auto& b = truth.nodes[static_cast<size_t>(e[1])];
    // Clockwise from north (−v): atan2(du, −dv), as a fraction of a turn in [0, 1).
    double h = std::atan2(b.u - a.u, -(b.v - a.v)) / (2.0 * M_PI);
    if (h < 0.0) h += 1.0;
    cv::line(heading, {static_cast<int>(std::lround(a.u * 16)), static_cast<int>(std::lround(a.v * 16))},
             {static_cast<int>(std::lround(b.u * 16)), static_cast<int>(std::lround(b.v * 16))}, cv::Scalar(h),
             width_px, cv::LINE_8, 4);
  }
  return heading;
}

cv::Mat noisy_map(const cv::Mat& mask, double blur_sigma_px, double peak, double noise_fraction, uint64_t seed) {
  cv::Mat map;
  mask.convertTo(map, CV_32F, peak / 255.0);
  cv::GaussianBlur(map, map, {0, 0}, blur_sigma_px);
  Rng rng(seed);
  for (int v = 0; v < map.rows; ++v)
    for (int u = 0; u < map.cols; ++u)
      if (rng.bernoulli(noise_fraction)) map.at<float>(v, u) = rng.bernoulli(0.5) ? 1.0f : 0.0f;
  return map;
}

double apls(const metrics::Graph& truth, const metrics::Graph& pred, bool directed) {
  const metrics::TileMeasurement m = metrics::measure("tile", truth, &pred, metrics::MetricParams{});
  return m.values[directed ? metrics::kAplsDirected : metrics::kApls].value_or(-1.0);
}

}  // namespace nsg::test
