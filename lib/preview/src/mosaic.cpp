// Per-shard mosaics: a legend, then one card per tile (caption + 2 x 2 layer panels with
// the lane graph on top).
#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "draw.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/io/tile_members.h"
#include "nsg/metrics/io.h"

namespace nsg::preview {

namespace {

using detail::kLineHeightPx;

constexpr int kMarginPx = 12;   // around the image and between cards
constexpr int kPanelGapPx = 4;  // between the panels of one card

void MosaicOptionsCheck(const MosaicOptions& o) {
  NSG_CHECK(o.panel_px >= 32 && o.panel_px <= 1024, ConfigError, "", "panel_px", "32 … 1024");
  NSG_CHECK(o.max_columns >= 1 && o.max_columns <= 64, ConfigError, "", "max_columns", "1 … 64");
}

std::vector<std::pair<std::string, Rgb>> legend_items(bool submission) {
  std::vector<std::pair<std::string, Rgb>> items;
  if (submission) {
    items.push_back({"ground truth", kGtEdge});
    items.push_back({"prediction", kPredEdge});
  } else {
    items.push_back({"lane edge (arrow = direction)", kGraphEdge});
    items.push_back({"lane node", kGraphNode});
  }
  items.push_back({"no data", kNoData});
  items.push_back({"LiDAR low", {64, 64, 64}});
  items.push_back({"LiDAR high", {255, 255, 255}});
  for (int c = 0; c < kSemanticClassCount; ++c) items.push_back({semantic_name(c), semantic_color(c)});
  for (int q = 0; q < 4; ++q) items.push_back({strprintf("heading %.2f", q * 0.25), heading_color(q * 0.25)});
  return items;
}

// Tile rasters are validated here against their io declaration (io/tile_members.h): a
// wrong band count or type is a malformed member.
io::Raster layer_raster(const io::DatasetTile& tile, const std::string& suffix) {
  const io::TileMember* member = io::find_tile_member(suffix);
  NSG_CHECK(member != nullptr && member->raster, InternalError, suffix, "", "a raster member of io::tile_members()");
  io::Raster r = tile.raster(suffix);
  NSG_CHECK(r.bands == member->bands && r.type == member->dtype, ParseError, tile.key + "." + suffix, "raster",
            strprintf("%d band(s) of %s", member->bands, io::dtype_name(member->dtype)));
  return r;
}

Rgb lidar_grey(uint8_t v) {
  if (v == 0) return kNoData;
  const auto g = static_cast<uint8_t>(64 + (v * 191 + 127) / 255);
  return {g, g, g};
}

// One layer as a tile-sized RGB Mat; kNoData where the layer has none (or is absent).
cv::Mat layer_mat(const io::DatasetTile& tile, int layer, int size_px) {
  cv::Mat m(size_px, size_px, CV_8UC3, detail::scalar(kNoData));
  auto set = [&m](int i, Rgb c) { m.at<cv::Vec3b>(i / m.cols, i % m.cols) = cv::Vec3b(c.r, c.g, c.b); };
  auto check = [&](const io::Raster& r, const std::string& suffix) {
    NSG_CHECK(r.width == size_px && r.height == size_px, ParseError, tile.key + "." + suffix, "size",
              strprintf("%d x %d like the LiDAR layer", size_px, size_px));
  };
  const int n = size_px * size_px;
  if (layer == kLidar || layer == kVehicle) {
    if (!tile.has("lidar.tif")) return m;
    const io::Raster lidar = layer_raster(tile, "lidar.tif");
    check(lidar, "lidar.tif");
    for (int i = 0; i < n; ++i) {
      Rgb g = lidar_grey(lidar.data[i]);
      if (layer == kVehicle) g = detail::blend(kNoData, g, 0.5);  // dimmed: headings stand out
      set(i, g);
    }
    if (layer == kLidar || !tile.has("vehicle.tif")) return m;
    const io::Raster vehicle = layer_raster(tile, "vehicle.tif");
    check(vehicle, "vehicle.tif");
    const auto* h = reinterpret_cast<const float*>(vehicle.data.data());
    for (int i = 0; i < n; ++i)
      if (h[i] >= 0.0f) set(i, heading_color(h[i]));  // −1 = no vehicle: LiDAR shows through
  } else if (layer == kRgb) {
    if (!tile.has("rgb.tif")) return m;
    const io::Raster rgb = layer_raster(tile, "rgb.tif");
    check(rgb, "rgb.tif");
    for (int i = 0; i < n; ++i) {
      const Rgb c{rgb.data[3 * i], rgb.data[3 * i + 1], rgb.data[3 * i + 2]};
      if (!(c == Rgb{0, 0, 0})) set(i, c);
    }
  } else {
    if (!tile.has("semantic.tif")) return m;
    const io::Raster sem = layer_raster(tile, "semantic.tif");
    check(sem, "semantic.tif");
    for (int i = 0; i < n; ++i) set(i, semantic_color(sem.data[i]));
  }
  return m;
}

// Coverage bit flags (1 LiDAR, 2 RGB, 4 semantics) as colour channels; 0 = no data.
cv::Mat coverage_mat(const io::DatasetTile& tile, int size_px) {
  cv::Mat m(size_px, size_px, CV_8UC3, detail::scalar(kNoData));
  if (!tile.has("coverage.tif")) return m;
  const io::Raster cov = layer_raster(tile, "coverage.tif");
  NSG_CHECK(cov.width == size_px && cov.height == size_px, ParseError, tile.key + ".coverage.tif", "size",
            strprintf("%d x %d like the LiDAR layer", size_px, size_px));
  for (int i = 0; i < size_px * size_px; ++i) {
    const uint8_t f = cov.data[i];
    if (f == 0) continue;
    const Rgb c = coverage_color(f);
    m.at<cv::Vec3b>(i / size_px, i % size_px) = cv::Vec3b(c.r, c.g, c.b);
  }
  return m;
}

std::string show(const std::optional<double>& v) { return v ? strprintf("%.3f", *v) : std::string("n/a"); }

std::vector<std::string> caption_of(const CardInput& in, const io::TileMeta& meta, const metrics::Graph& gt) {
  std::vector<std::string> lines{in.tile->key};
  lines.push_back(strprintf("coverage L %.1f%% R %.1f%% S %.1f%% | %zu nodes %zu edges", 100.0 * meta.coverage_lidar,
                            100.0 * meta.coverage_rgb, 100.0 * meta.coverage_semantic, gt.nodes.size(),
                            gt.edges.size()));
  if (in.submission) {
    if (!in.prediction) {
      lines.push_back("prediction missing (scored as empty)");
    } else if (in.scores) {
      const auto& v = in.scores->values;
      lines.push_back("APLS " + show(v[metrics::kApls]) + "  F1 " + show(v[metrics::kF1]) + "  TOPO " +
                      show(v[metrics::kTopoF1]) + "  dir " + show(v[metrics::kDirectionAccuracy]));
    }
  }
  return lines;
}

void draw_card(cv::Mat& canvas, const CardInput& in, Card& card) {
  const io::DatasetTile& tile = *in.tile;
  const metrics::Graph gt = metrics::tile_graph(tile);
  card.caption = caption_of(in, tile.meta(), gt);
  const int size_px = tile.raster("lidar.tif").width;
  NSG_CHECK(size_px > 0, ParseError, tile.key + ".lidar.tif", "size", "a positive width");
  const int panel_px = card.panels[0].width;
  card.scale = static_cast<double>(panel_px) / size_px;

  for (size_t i = 0; i < card.caption.size(); ++i)
    detail::put_text(canvas, card.caption[i], card.caption_rect.x + 2,
                     card.caption_rect.y + static_cast<int>(i + 1) * kLineHeightPx - 3);
  for (int layer = 0; layer < kLayerCount; ++layer) {
    const Rect& p = card.panels[layer];
    cv::Mat roi = canvas(cv::Rect(p.x, p.y, p.width, p.height));
    cv::resize(layer_mat(tile, layer, size_px), roi, roi.size(), 0, 0, cv::INTER_NEAREST);
    if (in.submission) {
      detail::draw_graph(roi, gt, card.scale, {kGtEdge, kGtEdge, 4, 3, 8.0});
      if (in.prediction) detail::draw_graph(roi, *in.prediction, card.scale, {kPredEdge, kPredEdge, 2, 2, 7.0});
    } else {
      detail::draw_graph(roi, gt, card.scale, {kGraphEdge, kGraphNode, 2, 2, 7.0});
    }
    cv::rectangle(canvas, cv::Rect(p.x - 1, p.y - 1, p.width + 2, p.height + 2), detail::scalar(kInk), 1);
  }
}

}  // namespace

void MosaicOptions::validate() const { MosaicOptionsCheck(*this); }

Image render_tile_layer(const io::DatasetTile& tile, const std::string& layer) {
  const int size_px = tile.raster("lidar.tif").width;
  NSG_CHECK(size_px > 0, ParseError, tile.key + ".lidar.tif", "size", "a positive width");
  cv::Mat m;
  if (layer == "lidar") m = layer_mat(tile, kLidar, size_px);
  else if (layer == "rgb") m = layer_mat(tile, kRgb, size_px);
  else if (layer == "semantic") m = layer_mat(tile, kSemantic, size_px);
  else if (layer == "vehicle") m = layer_mat(tile, kVehicle, size_px);
  else if (layer == "coverage") m = coverage_mat(tile, size_px);
  else throw ConfigError("", "layer", "lidar, rgb, semantic, vehicle or coverage, got '" + layer + "'");
  Image image = detail::blank_image(size_px, size_px, kNoData);
  m.copyTo(detail::wrap(image));
  return image;
}

Mosaic render_mosaic(const std::string& name, const std::vector<CardInput>& inputs, const MosaicOptions& options) {
  options.validate();
  NSG_CHECK(!inputs.empty(), ConfigError, "", name, "at least one tile to render");
  const bool submission = inputs.front().submission;
  const int n = static_cast<int>(inputs.size());
  const int cols = std::min(options.max_columns, n);
  const int rows = (n + cols - 1) / cols;
  const int panel = options.panel_px;
  const int caption_h = (submission ? 3 : 2) * kLineHeightPx + 2;
  const int card_w = 2 * panel + kPanelGapPx;
  const int card_h = caption_h + 2 * panel + kPanelGapPx;
  const int width = 2 * kMarginPx + cols * card_w + (cols - 1) * kMarginPx;

  Mosaic mosaic;
  mosaic.name = name;
  const std::string title =
      strprintf("NuScenesGraph %s: %s, %d tile(s). Panels: LiDAR intensity | RGB / semantics | vehicle heading",
                submission ? "submission" : "preview", name.c_str(), n);
  const int legend_top = kMarginPx + kLineHeightPx + 4;
  int legend_bottom = 0;
  const auto items = legend_items(submission);
  detail::legend(nullptr, items, kMarginPx, legend_top, width - 2 * kMarginPx, &legend_bottom);
  const int cards_top = legend_bottom + kMarginPx;
  const int height = cards_top + rows * card_h + (rows - 1) * kMarginPx + kMarginPx;

  mosaic.image = detail::blank_image(width, height, kPaper);
  cv::Mat canvas = detail::wrap(mosaic.image);
  detail::put_text(canvas, title, kMarginPx, kMarginPx + kLineHeightPx - 3);
  mosaic.legend = detail::legend(&canvas, items, kMarginPx, legend_top, width - 2 * kMarginPx, &legend_bottom);

  for (int i = 0; i < n; ++i) {
    NSG_CHECK(inputs[i].tile != nullptr, InternalError, "", name, "a tile for every card");
    Card card;
    card.key = inputs[i].tile->key;
    const int x0 = kMarginPx + (i % cols) * (card_w + kMarginPx);
    const int y0 = cards_top + (i / cols) * (card_h + kMarginPx);
    card.caption_rect = {x0, y0, card_w, caption_h};
    for (int layer = 0; layer < kLayerCount; ++layer)
      card.panels[layer] = {x0 + (layer % 2) * (panel + kPanelGapPx),
                            y0 + caption_h + (layer / 2) * (panel + kPanelGapPx), panel, panel};
    draw_card(canvas, inputs[i], card);
    mosaic.cards.push_back(std::move(card));
  }
  return mosaic;
}

}  // namespace nsg::preview
