#pragma once
// Known lane graphs on a 256 x 256 tile and their masks drawn with a given width, for
// scoring graphify's output against the graph it came from.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/metrics/graph.h"

namespace nsg::test {

struct GraphCase {
  std::string name;
  metrics::Graph truth;  // pixel (u, v); each polyline's edges one way
};

// Straight lane, a curve, a Y split, two parallel lanes 17.5 px (3.5 m) apart, two lanes
// crossing at right angles (no shared node).
std::vector<GraphCase> graph_cases();
// `pieces` + 1 points evenly from a to b.
std::vector<cv::Point2d> line(cv::Point2d a, cv::Point2d b, int pieces);
// Appends the line a → b as pieces + 1 new nodes and one-way edges.
void add_line(metrics::Graph& g, cv::Point2d a, cv::Point2d b, int pieces);
// The truth's edges drawn as lines `width_px` wide: CV_8U 0 / 255 of size_px x size_px.
cv::Mat draw_mask(const metrics::Graph& truth, int width_px, int size_px = 256);
// A probability map: the mask blurred (σ = blur_sigma_px), scaled by `peak`, then
// salt-and-pepper noise on a `noise_fraction` of the pixels (seeded, nsg::Rng).
cv::Mat noisy_map(const cv::Mat& mask, double blur_sigma_px, double peak, double noise_fraction, uint64_t seed);
// The heading of each truth edge drawn along it `width_px` wide (the dataset's vehicle
// layer convention: a fraction of a turn clockwise from north), −1 elsewhere; CV_32F.
cv::Mat draw_heading(const metrics::Graph& truth, int width_px, int size_px = 256);
// APLS (undirected, metrics::kApls; or directed, kAplsDirected) of `pred` against `truth`
// on a 256-px tile.
double apls(const metrics::Graph& truth, const metrics::Graph& pred, bool directed = false);

}  // namespace nsg::test
