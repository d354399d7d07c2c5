#include "draw.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nsg/core/coverage_bits.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg::preview {

Rgb Image::at(int x, int y) const {
  NSG_CHECK(x >= 0 && y >= 0 && x < width && y < height, DataError, "", strprintf("pixel (%d, %d)", x, y),
            strprintf("inside the %d x %d image", width, height));
  const size_t i = (static_cast<size_t>(y) * width + x) * 3;
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

std::array<double, 2> Card::to_image(int layer, double u, double v) const {
  const Rect& p = panels.at(layer);
  return {p.x + (u + 0.5) * scale - 0.5, p.y + (v + 0.5) * scale - 0.5};
}

std::array<double, 2> Overview::to_image(double x_m, double y_m) const {
  return {map_rect.x + (x_m - x_west_m) / m_per_px - 0.5, map_rect.y + (y_north_m - y_m) / m_per_px - 0.5};
}

Rgb semantic_color(int class_id) {
  if (class_id < 0 || class_id >= kSemanticClassCount) return kNoData;
  const auto& c = nsg::kSemanticClasses[class_id].color;
  return {c[0], c[1], c[2]};
}

const char* semantic_name(int class_id) {
  if (class_id < 0 || class_id >= kSemanticClassCount) return "";
  return nsg::kSemanticClasses[class_id].name.data();  // a literal: NUL-terminated
}

Rgb split_color(const std::string& split) {
  if (split == "train") return {0, 114, 178};
  if (split == "val") return {0, 158, 115};
  if (split == "test") return {213, 94, 0};
  return {128, 128, 128};
}

Rgb region_fill(const std::string& split) {
  return detail::blend(kMapBackground, split_color(split), kRegionFillAlpha);
}

const std::vector<OverlayColor>& overlay_colors() {
  static const std::vector<OverlayColor> kOverlays = {
      {"gt", "ground truth (arrow: direction)", kGtEdge, false},
      {"missed", "missed ground truth", kMissedGtEdge, true},
      {"pred", "prediction, direction correct", kPredEdge, false},
      {"wrong_direction", "prediction, wrong direction", kWrongDirectionEdge, false},
      {"unmatched", "prediction, unmatched", kUnmatchedEdge, true},
      {"baseline", "baseline's prediction", kBaselineEdge, true},
      {"lane_change", "lane change (neighbouring lane, same direction)", kLaneChangeEdge, true},
      {"junction", "junction node (split, merge)", kJunctionNode, false},
  };
  return kOverlays;
}

namespace {

// sRGB component → CIELAB's f(t) input: linear light.
double srgb_to_linear(uint8_t c) {
  const double v = c / 255.0;
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

std::array<double, 3> to_lab(Rgb c) {
  const double r = srgb_to_linear(c.r), g = srgb_to_linear(c.g), b = srgb_to_linear(c.b);
  // XYZ relative to the D65 white point.
  const double x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
  const double y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
  const double z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
  const auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; };
  return {116.0 * f(y) - 16.0, 500.0 * (f(x) - f(y)), 200.0 * (f(y) - f(z))};
}

}  // namespace

double color_difference(Rgb a, Rgb b) {
  const auto la = to_lab(a), lb = to_lab(b);
  return std::sqrt((la[0] - lb[0]) * (la[0] - lb[0]) + (la[1] - lb[1]) * (la[1] - lb[1]) +
                   (la[2] - lb[2]) * (la[2] - lb[2]));
}

Rgb coverage_color(uint8_t flags) {
  if (flags == 0) return kNoData;
  const auto channel = [flags](uint8_t bit) { return static_cast<uint8_t>(flags & bit ? 230 : 40); };
  return {channel(kCoverageLidar), channel(kCoverageRgb), channel(kCoverageSemantic)};
}

Rgb heading_color(double heading) {
  const double h6 = std::clamp(heading - std::floor(heading), 0.0, 1.0) * 6.0;
  const int sector = std::min(5, static_cast<int>(h6));
  const auto up = static_cast<uint8_t>(std::lround(255.0 * (h6 - sector)));
  const auto down = static_cast<uint8_t>(255 - up);
  switch (sector) {
    case 0: return {255, up, 0};
    case 1: return {down, 255, 0};
    case 2: return {0, 255, up};
    case 3: return {0, down, 255};
    case 4: return {up, 0, 255};
    default: return {255, 0, down};
  }
}

std::vector<uint8_t> encode_png(const Image& image, int compression_level) {
  NSG_CHECK(
      image.width > 0 && image.height > 0 && image.rgb.size() == static_cast<size_t>(image.width) * image.height * 3,
      DataError, "", "image", "a non-empty RGB buffer");
  const cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> bytes;
  NSG_CHECK(cv::imencode(".png", bgr, bytes, {cv::IMWRITE_PNG_COMPRESSION, std::clamp(compression_level, 0, 9)}),
            InternalError, "", "png", "OpenCV to encode the image");
  return bytes;
}

namespace detail {

Image blank_image(int width, int height, Rgb fill) {
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(static_cast<size_t>(width) * height * 3);
  for (size_t i = 0; i < image.rgb.size(); i += 3) {
    image.rgb[i] = fill.r;
    image.rgb[i + 1] = fill.g;
    image.rgb[i + 2] = fill.b;
  }
  return image;
}

cv::Mat wrap(Image& image) { return cv::Mat(image.height, image.width, CV_8UC3, image.rgb.data()); }

cv::Scalar scalar(Rgb c) { return cv::Scalar(c.r, c.g, c.b); }

Rgb blend(Rgb under, Rgb over, double alpha) {
  auto mix = [alpha](uint8_t a, uint8_t b) { return static_cast<uint8_t>(std::lround(a + (b - a) * alpha)); };
  return {mix(under.r, over.r), mix(under.g, over.g), mix(under.b, over.b)};
}

void put_text(cv::Mat& mat, const std::string& text, int x, int y_baseline, Rgb color) {
  cv::putText(mat, text, {x, y_baseline}, cv::FONT_HERSHEY_SIMPLEX, kFontScale, scalar(color), 1, cv::LINE_AA);
}

int text_width(const std::string& text) {
  int baseline = 0;
  return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, kFontScale, 1, &baseline).width;
}

std::vector<LegendEntry> legend(cv::Mat* mat, const std::vector<std::pair<std::string, Rgb>>& items, int x, int y,
                                int width, int* bottom) {
  constexpr int kSwatchPx = 12, kGapPx = 5, kItemGapPx = 16;
  std::vector<LegendEntry> out;
  int cx = x, cy = y;
  for (const auto& [label, color] : items) {
    const int item_w = kSwatchPx + kGapPx + text_width(label) + kItemGapPx;
    if (cx > x && cx + item_w > x + width) {
      cx = x;
      cy += kLineHeightPx + 4;
    }
    LegendEntry e{label, color, {cx, cy + 2, kSwatchPx, kSwatchPx}};
    if (mat) {
      const cv::Rect r(e.swatch.x, e.swatch.y, e.swatch.width, e.swatch.height);
      cv::rectangle(*mat, r, scalar(color), cv::FILLED);
      cv::rectangle(*mat, cv::Rect(r.x - 1, r.y - 1, r.width + 2, r.height + 2), scalar(kInk), 1);
      put_text(*mat, label, cx + kSwatchPx + kGapPx, cy + kLineHeightPx - 3);
    }
    out.push_back(e);
    cx += item_w;
  }
  *bottom = cy + kLineHeightPx + 4;
  return out;
}

void draw_graph(cv::Mat& panel, const metrics::Graph& graph, double scale, const GraphStyle& style) {
  auto at = [&](size_t i) {
    const metrics::Point& p = graph.nodes[i];
    return cv::Point(static_cast<int>(std::lround((p.u + 0.5) * scale - 0.5)),
                     static_cast<int>(std::lround((p.v + 0.5) * scale - 0.5)));
  };
  for (const auto& e : graph.edges) {
    if (e[0] < 0 || e[1] < 0 || static_cast<size_t>(e[0]) >= graph.nodes.size() ||
        static_cast<size_t>(e[1]) >= graph.nodes.size() || e[0] == e[1])
      continue;  // invalid edges are the validator's business, not the preview's
    const cv::Point a = at(e[0]), b = at(e[1]);
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    if (len < 1.0) continue;
    cv::arrowedLine(panel, a, b, scalar(style.edge), style.edge_thickness_px, cv::LINE_8, 0,
                    std::min(0.45, style.arrow_tip_px / len));
  }
  for (size_t i = 0; i < graph.nodes.size(); ++i)
    cv::circle(panel, at(i), style.node_radius_px, scalar(style.node), cv::FILLED, cv::LINE_8);
}

}  // namespace detail
}  // namespace nsg::preview
