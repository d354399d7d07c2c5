// Side-by-side BEV panels of `inspect layers --png` (docs/real-data.md's picture of the
// real key frame): LiDAR intensity in grey and the camera RGB, no data dark, a caption over
// each and a scale bar.
#include <algorithm>
#include <cmath>

#include "draw.h"
#include "nsg/core/strings.h"

#include <opencv2/imgproc.hpp>

namespace nsg::preview {

void LayerPanelsOptions::validate() const {
  if (max_panel_px < 64 || max_panel_px > 8192) throw ConfigError("", "max_panel_px", "expected 64..8192 px");
  if (!(resolution_m > 0.0)) throw ConfigError("", "resolution_m", "expected > 0 m");
}

namespace {

constexpr int kMarginPx = 8;

// The panel content at `scale` panel px per raster px (nearest: cells stay crisp).
void fill_panel(cv::Mat& panel, const LayerPanelsInput& in, bool rgb, double scale) {
  for (int y = 0; y < panel.rows; ++y) {
    const int sy = std::min(in.height - 1, static_cast<int>(y / scale));
    auto* row = panel.ptr<cv::Vec3b>(y);
    for (int x = 0; x < panel.cols; ++x) {
      const size_t i = static_cast<size_t>(sy) * in.width + std::min(in.width - 1, static_cast<int>(x / scale));
      if (rgb) {
        const bool data = in.rgb[3 * i] | in.rgb[3 * i + 1] | in.rgb[3 * i + 2];
        row[x] = data ? cv::Vec3b(in.rgb[3 * i], in.rgb[3 * i + 1], in.rgb[3 * i + 2])
                      : cv::Vec3b(kNoData.r, kNoData.g, kNoData.b);
      } else {
        // Intensity is mostly dark (paint and signs are the bright returns): a square-root
        // stretch shows the asphalt too; 0 stays "no data".
        const uint8_t v = in.lidar[i];
        const auto g = static_cast<uint8_t>(std::lround(std::sqrt(v / 255.0) * 205.0 + 50.0));
        row[x] = v ? cv::Vec3b(g, g, g) : cv::Vec3b(kNoData.r, kNoData.g, kNoData.b);
      }
    }
  }
}

// A bar of a round length (10, 20, 50 m …) near a fifth of the panel width.
void scale_bar(cv::Mat& mat, int x, int y, double px_per_m, int panel_width) {
  double length_m = 1.0;
  for (double step : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0})
    if (step * px_per_m <= panel_width / 5.0) length_m = step;
  const int w = static_cast<int>(std::lround(length_m * px_per_m));
  cv::rectangle(mat, cv::Rect(x, y, w, 4), detail::scalar(kInk), cv::FILLED);
  detail::put_text(mat, strprintf("%g m", length_m), x + w + 6, y + 6);
}

}  // namespace

Image render_layer_panels(const LayerPanelsInput& in, const LayerPanelsOptions& options) {
  options.validate();
  if (in.width <= 0 || in.height <= 0 || in.lidar.size() != static_cast<size_t>(in.width) * in.height ||
      in.rgb.size() != 3 * in.lidar.size())
    throw InternalError("", "", "render_layer_panels: rasters of the stated size");
  const double scale = std::min(1.0 * options.max_panel_px / std::max(in.width, in.height), 4.0);
  const int pw = std::max(1, static_cast<int>(std::lround(in.width * scale)));
  const int ph = std::max(1, static_cast<int>(std::lround(in.height * scale)));
  const int caption_h = detail::kLineHeightPx * static_cast<int>(in.title.empty() ? 1 : 2) + kMarginPx;
  Image image = detail::blank_image(3 * kMarginPx + 2 * pw, caption_h + ph + 3 * kMarginPx + 8, kPaper);
  cv::Mat mat = detail::wrap(image);
  int y = kMarginPx + detail::kLineHeightPx - 4;
  if (!in.title.empty()) {
    detail::put_text(mat, in.title, kMarginPx, y);
    y += detail::kLineHeightPx;
  }
  detail::put_text(mat, "LiDAR intensity (lowest point per cell)", kMarginPx, y);
  detail::put_text(mat, "RGB from the key-frame cameras", 2 * kMarginPx + pw, y);
  const int top = caption_h;
  for (int k = 0; k < 2; ++k) {
    cv::Mat panel = mat(cv::Rect(kMarginPx + k * (pw + kMarginPx), top, pw, ph));
    fill_panel(panel, in, k == 1, scale);
  }
  scale_bar(mat, kMarginPx, top + ph + kMarginPx, scale / options.resolution_m, pw);
  return image;
}

}  // namespace nsg::preview
