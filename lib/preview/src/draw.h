#pragma once
// OpenCV drawing helpers shared by mosaics and overviews (private to lib/preview). Mats
// wrap Image buffers and hold RGB (not OpenCV's usual BGR); encode_png swaps at the end.
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "nsg/core/error.h"
#include "nsg/metrics/graph.h"
#include "nsg/preview/preview.h"

namespace nsg::preview::detail {

inline constexpr int kLineHeightPx = 16;  // one caption / legend text line
inline constexpr double kFontScale = 0.42;

Image blank_image(int width, int height, Rgb fill);
cv::Mat wrap(Image& image);  // shares the buffer
cv::Scalar scalar(Rgb c);
Rgb blend(Rgb under, Rgb over, double alpha);

// Text with its baseline at (x, y_baseline), in kInk unless told.
void put_text(cv::Mat& mat, const std::string& text, int x, int y_baseline, Rgb color = kInk);
int text_width(const std::string& text);

// Lays out swatch + label items left to right from (x, y), wrapping at x + width; draws
// them when `mat` is non-null. Returns the entries with their swatches and sets `bottom`.
std::vector<LegendEntry> legend(cv::Mat* mat, const std::vector<std::pair<std::string, Rgb>>& items, int x, int y,
                                int width, int* bottom);

struct GraphStyle {
  Rgb edge;
  Rgb node;
  int edge_thickness_px = 2;
  int node_radius_px = 2;
  double arrow_tip_px = 7.0;  // arrowhead length; edges show their direction
};
// Draws `graph` (tile pixel coordinates) into `panel`, scaled by `scale` panel px per tile
// px; clipped to the panel.
void draw_graph(cv::Mat& panel, const metrics::Graph& graph, double scale, const GraphStyle& style);

}  // namespace nsg::preview::detail
