#pragma once
// Previews people can look at: per-shard mosaics of a dataset's tiles (every
// layer with the lane graph on top), per-location overviews (LiDAR coverage, split regions,
// crop footprints, lane graph, scale bar, north arrow) and submission overlays (GT vs
// prediction with the tile's scores, sortable worst first). Images are plain RGB buffers;
// OpenCV stays inside lib/preview. Output bytes are deterministic (no time stamps).
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nsg/core/semantic_classes.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/graph.h"
#include "nsg/metrics/measure.h"

namespace nsg::preview {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb&) const = default;
};

struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
  bool contains(int px, int py) const { return px >= x && py >= y && px < x + width && py < y + height; }
};

// 8-bit RGB, row-major, pixel-interleaved.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
  Rgb at(int x, int y) const;  // throws DataError outside the image
};

// Colours. Graph colours avoid the semantic palette.
inline constexpr Rgb kGraphEdge{0, 255, 255};
inline constexpr Rgb kGraphNode{255, 255, 0};
inline constexpr Rgb kNoData{32, 32, 32};
inline constexpr Rgb kPaper{255, 255, 255};
inline constexpr Rgb kInk{0, 0, 0};
inline constexpr Rgb kMapBackground{235, 235, 235};
inline constexpr Rgb kCropOutline{0, 0, 0};
inline constexpr double kRegionFillAlpha = 0.35;

// The overlays compared in previews and the report: ground truth in Okabe-Ito sky blue,
// the prediction in spring green (the former orange vanished on the semantic layer's
// orange road and lane markings), errors in magenta and yellow. The report draws each over
// a black casing, so every one keeps a contrast of at least kOverlayMinContrast (CIE76 ΔE)
// on every colour of every layer's palette, the line or its casing (test:
// OverlayColours.StandOutOnEveryLayer).
inline constexpr Rgb kGtEdge{86, 180, 233};
inline constexpr Rgb kMissedGtEdge{0, 64, 192};
inline constexpr Rgb kPredEdge{0, 255, 128};
inline constexpr Rgb kWrongDirectionEdge{255, 0, 255};
inline constexpr Rgb kUnmatchedEdge{240, 228, 66};
inline constexpr Rgb kBaselineEdge{255, 255, 255};
inline constexpr Rgb kLaneChangeEdge{230, 159, 0};  // graph.json's lane_changes
inline constexpr Rgb kJunctionNode{255, 64, 64};    // split / merge nodes
inline constexpr Rgb kOverlayCasing{0, 0, 0};
inline constexpr double kOverlayMinContrast = 40.0;
// The report's overlays by the name its page and legend use, in drawing order.
struct OverlayColor {
  const char* name;   // "gt", "missed", "pred", "wrong_direction", "unmatched", "baseline", "lane_change", "junction"
  const char* label;  // the legend's words
  Rgb color;
  bool dashed;
};
const std::vector<OverlayColor>& overlay_colors();
// CIE76 colour difference (ΔE*ab, sRGB → CIELAB under D65): ~2 is just noticeable, 40 is
// plainly another colour.
double color_difference(Rgb a, Rgb b);

// The palette of the semantic classes (nsg/core/semantic_classes.h); kNoData for 255 / unknown.
Rgb semantic_color(int class_id);
const char* semantic_name(int class_id);  // "" for unknown ids
inline constexpr int kSemanticClassCount = nsg::kSemanticClassCount;
// Okabe-Ito: train blue, val bluish green, test vermillion; other splits grey.
Rgb split_color(const std::string& split);
// What a split region's interior shows where no tile lies: split_color blended into
// kMapBackground with kRegionFillAlpha.
Rgb region_fill(const std::string& split);
// Vehicle heading in [0, 1) as a fully saturated hue (0 = red, 1/3 = green, 2/3 = blue).
Rgb heading_color(double heading);
// A coverage.tif value as a colour: each bit (core/coverage_bits.h) lights its channel,
// LiDAR red, RGB green, semantics blue; kNoData for 0 (no layer has data).
Rgb coverage_color(uint8_t flags);

struct LegendEntry {
  std::string label;
  Rgb color;
  Rect swatch;  // filled with `color`
};

enum Layer : int { kLidar, kRgb, kSemantic, kVehicle, kLayerCount };

// One tile's card: caption lines on top, then the layers in a 2 x 2 grid
// (LiDAR, RGB / semantics, vehicle heading), each with the graph drawn over it.
struct Card {
  std::string key;
  std::vector<std::string> caption;
  Rect caption_rect;
  std::array<Rect, kLayerCount> panels{};
  double scale = 1.0;  // panel pixels per tile pixel
  // Image position of tile pixel (u, v) (integer = pixel centre) in panel `layer`.
  std::array<double, 2> to_image(int layer, double u, double v) const;
};

struct Mosaic {
  std::string name;  // file stem, e.g. "test-000000"
  Image image;
  std::vector<Card> cards;
  std::vector<LegendEntry> legend;
};

struct MosaicOptions {
  int panel_px = 240;     // side of one layer panel; 8 cards of 2 panels ≈ 4K px wide
  int max_columns = 8;    // cards per row
  void validate() const;  // throws ConfigError
};

// What one card shows. In submission mode `prediction` (nullptr = missing from the
// submission) is drawn over the GT and `scores` fill the caption.
struct CardInput {
  const io::DatasetTile* tile = nullptr;
  bool submission = false;
  const metrics::Graph* prediction = nullptr;
  const metrics::TileMeasurement* scores = nullptr;
};

// Throws ParseError naming the tile member when a layer or the graph is malformed.
Mosaic render_mosaic(const std::string& name, const std::vector<CardInput>& cards, const MosaicOptions& options);

struct OverviewOptions {
  int max_map_px = 2000;  // longest side of the map area
  void validate() const;  // throws ConfigError
};

struct Overview {
  std::string location;
  Image image;
  Rect map_rect;           // where the map is drawn
  double x_west_m = 0.0;   // map metres at map_rect's left edge
  double y_north_m = 0.0;  // map metres at map_rect's top edge
  double m_per_px = 1.0;
  std::vector<std::array<double, 4>> crops;  // bounds_m of every tile drawn
  std::vector<LegendEntry> legend;
  // Image position of map point (x_m, y_m).
  std::array<double, 2> to_image(double x_m, double y_m) const;
};

// One location of the manifest: its split regions, the LiDAR of every tile of `split`
// ("" = all) placed by its meta bounds_m, crop outlines and the tiles' lane graphs.
// Throws ConfigError if the manifest has no such location.
Overview render_overview(const io::Dataset& dataset, const std::string& location, const std::string& split,
                         const OverviewOptions& options);

// Two BEV panels side by side (`inspect layers --png`): LiDAR intensity and camera RGB of
// one raster window, row 0 north, no data dark, with a scale bar.
struct LayerPanelsInput {
  int width = 0, height = 0;   // raster pixels
  std::vector<uint8_t> lidar;  // width × height, 0 = no data
  std::vector<uint8_t> rgb;    // width × height × 3, 0,0,0 = no data
  std::string title;           // a caption line over both panels ("" = none)
};
struct LayerPanelsOptions {
  int max_panel_px = 900;     // longest side of one panel (upscaled by at most 4×)
  double resolution_m = 0.2;  // raster metres per pixel, for the scale bar
  void validate() const;      // throws ConfigError
};
// Throws InternalError when the rasters do not have the stated size.
Image render_layer_panels(const LayerPanelsInput& input, const LayerPanelsOptions& options);

// One layer of a tile at its own size (one image pixel per tile pixel), coloured as in the
// mosaics: "lidar", "rgb", "semantic", "vehicle" (headings over dimmed LiDAR) or
// "coverage" (bit flags as colour channels: LiDAR red, RGB green, semantics blue). A layer
// the tile lacks is all kNoData. Throws ParseError naming the member when it is malformed,
// ConfigError for an unknown layer name.
Image render_tile_layer(const io::DatasetTile& tile, const std::string& layer);
inline constexpr const char* kTileLayerNames[] = {"lidar", "rgb", "semantic", "vehicle", "coverage"};

// PNG bytes (deterministic for identical images). zlib level 1 is about 3× faster than 6 for
// somewhat larger files (the report's thousands of tile layers).
std::vector<uint8_t> encode_png(const Image& image, int compression_level = 6);

// `tiles` reordered worst first by the metric named `metric` (as in the score report:
// "apls", "f1", …; Chamfer distances count larger as worse); undefined values last, ties
// by key. Throws ConfigError for an unknown name.
std::vector<metrics::TileMeasurement> worst_first(std::vector<metrics::TileMeasurement> tiles,
                                                  const std::string& metric);

struct PreviewOptions {
  std::string split;         // "" = all splits
  std::optional<int> shard;  // the shard numbered N (name "<split>-NNNNNN") only
  int max_tiles = 64;        // per image
  bool overview = false;     // per-location overviews instead of mosaics
  std::string submission;    // submission JSON: one GT-vs-prediction mosaic
  std::string sort;          // with a submission: a metric name, worst first ("" = key order)
  bool progress = false;     // a progress line on stderr (the CLI's)
  MosaicOptions mosaic;
  OverviewOptions overview_options;
  void validate() const;  // throws ConfigError
};

// Writes <out>/<shard>.png per shard, or <out>/overview-<location>.png per location, or
// <out>/submission-<split|all>.png; returns the files written, in order.
std::vector<std::filesystem::path> write_previews(const std::filesystem::path& dataset,
                                                  const std::filesystem::path& out_dir, const PreviewOptions& options);

}  // namespace nsg::preview
