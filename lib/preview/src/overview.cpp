// Per-location overviews: split regions, LiDAR coverage of every tile placed by its
// bounds_m (the dataset holds no full-location raster), crop outlines, the tiles' lane
// graphs in map metres, a scale bar, a north arrow and a legend.
#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "draw.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/io/manifest.h"

namespace nsg::preview {

namespace {

using detail::kLineHeightPx;
constexpr int kMarginPx = 16;
constexpr int kLegendWidthPx = 260;
constexpr Rgb kOverviewLane{200, 0, 120};  // magenta: visible on grey LiDAR and on the fills

using io::Region;

struct Segment {
  double x0, y0, x1, y1;
};

// What streaming the tiles of one location collects.
struct TileLayers {
  std::vector<uint8_t> lidar_max;  // per map pixel, 0 = none
  std::vector<std::array<double, 4>> crops;
  std::vector<Segment> lanes;
};

void add_tile(const io::DatasetTile& tile, const io::TileMeta& meta, const Overview& ov, TileLayers& acc) {
  const std::array<double, 4>& b = meta.bounds_m;
  acc.crops.push_back(b);
  const int map_w = ov.map_rect.width, map_h = ov.map_rect.height;
  if (tile.has("lidar.tif")) {
    const io::Raster lidar = tile.raster("lidar.tif");
    NSG_CHECK(lidar.type == io::SampleType::kUInt8 && lidar.bands == 1, ParseError, tile.key + ".lidar.tif", "raster",
              "1 band of uint8");
    const double res_x = (b[2] - b[0]) / lidar.width, res_y = (b[3] - b[1]) / lidar.height;
    for (int r = 0; r < lidar.height; ++r)
      for (int c = 0; c < lidar.width; ++c) {
        const uint8_t v = lidar.data[static_cast<size_t>(r) * lidar.width + c];
        if (v == 0) continue;
        const double x = b[0] + (c + 0.5) * res_x, y = b[3] - (r + 0.5) * res_y;
        const auto mx = static_cast<int>(std::floor((x - ov.x_west_m) / ov.m_per_px));
        const auto my = static_cast<int>(std::floor((ov.y_north_m - y) / ov.m_per_px));
        if (mx < 0 || my < 0 || mx >= map_w || my >= map_h) continue;
        uint8_t& m = acc.lidar_max[static_cast<size_t>(my) * map_w + mx];
        m = std::max(m, v);  // max keeps sparse returns visible after downsampling
      }
  }
  if (tile.has("graph.json")) {
    const graph::TileGraph g = tile.graph();
    for (const graph::TileEdge& e : g.edges) {
      const graph::TileNode &s = g.nodes[static_cast<size_t>(e.source)], &t = g.nodes[static_cast<size_t>(e.target)];
      acc.lanes.push_back({s.x_m, s.y_m, t.x_m, t.y_m});
    }
  }
}

double nice_length_m(double target_m) {
  const double p = std::pow(10.0, std::floor(std::log10(target_m)));
  for (double f : {5.0, 2.0, 1.0})
    if (f * p <= target_m) return f * p;
  return p;
}

cv::Point to_px(const Overview& ov, double x, double y) {
  const auto p = ov.to_image(x, y);
  return {static_cast<int>(std::lround(p[0])), static_cast<int>(std::lround(p[1]))};
}

void draw_scale_and_north(cv::Mat& canvas, const Overview& ov) {
  const Rect& m = ov.map_rect;
  const double len_m = nice_length_m(m.width * ov.m_per_px / 5.0);
  const int len_px = static_cast<int>(std::lround(len_m / ov.m_per_px));
  const int x = m.x + 12, y = m.y + m.height - 14;
  cv::rectangle(canvas, cv::Rect(x - 4, y - 20, len_px + 8 + detail::text_width("000 m"), 28), detail::scalar(kPaper),
                cv::FILLED);
  cv::rectangle(canvas, cv::Rect(x, y - 3, len_px, 6), detail::scalar(kInk), cv::FILLED);
  detail::put_text(canvas, format_double(len_m) + " m", x, y - 7);
  const int nx = m.x + m.width - 24, ny = m.y + 12;
  cv::rectangle(canvas, cv::Rect(nx - 12, ny - 4, 24, 52), detail::scalar(kPaper), cv::FILLED);
  cv::arrowedLine(canvas, {nx, ny + 44}, {nx, ny + 16}, detail::scalar(kInk), 2, cv::LINE_8, 0, 0.4);
  detail::put_text(canvas, "N", nx - 5, ny + 12);
}

// The manifest's entry of `location`; ConfigError when it has none.
const io::ManifestLocation& find_location(const io::Manifest& m, const std::string& manifest,
                                          const std::string& location) {
  const io::ManifestLocation* loc = m.location(location);
  NSG_CHECK(loc != nullptr, ConfigError, manifest, "locations", "a location named '" + location + "'");
  return *loc;
}

struct Extent {
  double x_w, y_s, x_e, y_n;  // m
};

// The bounds of the regions, or of the location's tiles when no region is recorded.
Extent location_extent(const io::Dataset& dataset, const std::string& manifest, const std::string& location,
                       const std::string& split, const std::vector<Region>& regions) {
  double x_w = std::numeric_limits<double>::infinity(), y_s = x_w, x_e = -x_w, y_n = -x_w;
  auto grow = [&](const std::array<double, 4>& b) {
    x_w = std::min(x_w, b[0]), y_s = std::min(y_s, b[1]), x_e = std::max(x_e, b[2]), y_n = std::max(y_n, b[3]);
  };
  for (const Region& r : regions) grow(r.bounds_m);
  // meta.location, not the key prefix: "boston-" would also match "boston-seaport-…".
  if (regions.empty())  // no regions recorded: the extent comes from the tiles themselves
    dataset.for_each_tile(split, [&](const io::DatasetTile& t) {
      if (const io::TileMeta meta = t.meta(); meta.location == location) grow(meta.bounds_m);
      return true;
    });
  NSG_CHECK(std::isfinite(x_w), DataError, manifest, location, "regions or tiles to draw");
  return {x_w, y_s, x_e, y_n};
}

// Sets the overview's scale, origin and map rectangle: the extent padded by 5 %, at the
// tiles' resolution or coarser so that the map fits options.max_map_px.
void place_map(Overview& ov, Extent e, const io::Manifest& m, const OverviewOptions& options) {
  const double pad_m = 0.05 * std::max(e.x_e - e.x_w, e.y_n - e.y_s);
  e.x_w -= pad_m, e.y_s -= pad_m, e.x_e += pad_m, e.y_n += pad_m;
  const double tile_res_m = m.tile_format.resolution_m;
  ov.m_per_px = std::max(tile_res_m, std::max(e.x_e - e.x_w, e.y_n - e.y_s) / options.max_map_px);
  ov.x_west_m = e.x_w;
  ov.y_north_m = e.y_n;
  const int map_w = static_cast<int>(std::ceil((e.x_e - e.x_w) / ov.m_per_px));
  const int map_h = static_cast<int>(std::ceil((e.y_n - e.y_s) / ov.m_per_px));
  const int map_top = kMarginPx + kLineHeightPx + 8;
  ov.map_rect = {kMarginPx, map_top, map_w, map_h};
}

// One entry per split with a region (in the regions' order), then the layers.
std::vector<std::pair<std::string, Rgb>> legend_items(const std::vector<Region>& regions) {
  std::vector<std::pair<std::string, Rgb>> items;
  std::vector<std::string> splits_seen;
  for (const Region& r : regions)
    if (std::find(splits_seen.begin(), splits_seen.end(), r.split) == splits_seen.end()) {
      splits_seen.push_back(r.split);
      items.push_back({r.split + " region", region_fill(r.split)});
    }
  items.push_back({"LiDAR low", {64, 64, 64}});
  items.push_back({"LiDAR high", {255, 255, 255}});
  items.push_back({"crop footprint (outline)", kCropOutline});
  items.push_back({"lane graph", kOverviewLane});
  items.push_back({"outside regions", kMapBackground});
  return items;
}

// Map bounds as a rectangle of map pixels, clipped to the map.
cv::Rect rect_px(const Overview& ov, const std::array<double, 4>& b) {
  // Pixel-edge rectangle (not centres): region fills tile exactly.
  const int x0 = static_cast<int>(std::lround((b[0] - ov.x_west_m) / ov.m_per_px));
  const int x1 = static_cast<int>(std::lround((b[2] - ov.x_west_m) / ov.m_per_px));
  const int y0 = static_cast<int>(std::lround((ov.y_north_m - b[3]) / ov.m_per_px));
  const int y1 = static_cast<int>(std::lround((ov.y_north_m - b[1]) / ov.m_per_px));
  return cv::Rect(x0, y0, std::max(1, x1 - x0), std::max(1, y1 - y0)) &
         cv::Rect(0, 0, ov.map_rect.width, ov.map_rect.height);
}

// Streams the split's tiles of `location` into their LiDAR maximum, crops and lanes.
TileLayers collect_tiles(const io::Dataset& dataset, const std::string& location, const std::string& split,
                         const Overview& ov, size_t* n_tiles) {
  TileLayers acc;
  acc.lidar_max.assign(static_cast<size_t>(ov.map_rect.width) * ov.map_rect.height, 0);
  dataset.for_each_tile(split, [&](const io::DatasetTile& t) {
    const io::TileMeta meta = t.meta();
    if (meta.location != location) return true;
    add_tile(t, meta, ov, acc);
    ++*n_tiles;
    return true;
  });
  return acc;
}

// LiDAR in grey (64 … 255) over the fills, then crop outlines, region outlines, lanes and
// region names on top.
void draw_map_layers(cv::Mat& map, const Overview& ov, const std::vector<Region>& regions, const TileLayers& acc) {
  const int map_w = ov.map_rect.width, map_h = ov.map_rect.height;
  for (int y = 0; y < map_h; ++y)
    for (int x = 0; x < map_w; ++x)
      if (const uint8_t v = acc.lidar_max[static_cast<size_t>(y) * map_w + x]; v > 0) {
        const auto g = static_cast<uint8_t>(64 + (v * 191 + 127) / 255);
        map.at<cv::Vec3b>(y, x) = cv::Vec3b(g, g, g);
      }
  for (const auto& b : acc.crops) cv::rectangle(map, rect_px(ov, b), detail::scalar(kCropOutline), 1);
  for (const Region& r : regions) cv::rectangle(map, rect_px(ov, r.bounds_m), detail::scalar(split_color(r.split)), 2);
  const int lane_px = ov.m_per_px <= 0.25 ? 2 : 1;
  for (const Segment& s : acc.lanes) {
    const cv::Point a = to_px(ov, s.x0, s.y0) - cv::Point(ov.map_rect.x, ov.map_rect.y);
    const cv::Point b = to_px(ov, s.x1, s.y1) - cv::Point(ov.map_rect.x, ov.map_rect.y);
    cv::line(map, a, b, detail::scalar(kOverviewLane), lane_px, cv::LINE_8);
  }
  for (const Region& r : regions) {
    const cv::Rect rp = rect_px(ov, r.bounds_m);
    detail::put_text(map, r.name, rp.x + 4, rp.y + kLineHeightPx, split_color(r.split));
  }
}

}  // namespace

void OverviewOptions::validate() const {
  NSG_CHECK(max_map_px >= 64 && max_map_px <= 16384, ConfigError, "", "max_map_px", "64 … 16384");
}

Overview render_overview(const io::Dataset& dataset, const std::string& location, const std::string& split,
                         const OverviewOptions& options) {
  options.validate();
  const std::string manifest = (dataset.root() / "manifest.json").string();
  const io::Manifest& m = dataset.manifest();
  const io::ManifestLocation& loc = find_location(m, manifest, location);
  const std::vector<Region>& regions = loc.regions;

  Overview ov;
  ov.location = location;
  place_map(ov, location_extent(dataset, manifest, location, split, regions), m, options);
  const int map_w = ov.map_rect.width, map_h = ov.map_rect.height, map_top = ov.map_rect.y;

  // Legend first: its height may exceed the map's.
  const std::vector<std::pair<std::string, Rgb>> items = legend_items(regions);
  const int legend_x = kMarginPx + map_w + kMarginPx;
  int legend_bottom = 0;
  detail::legend(nullptr, items, legend_x, map_top, kLegendWidthPx, &legend_bottom);
  const int width = legend_x + kLegendWidthPx + kMarginPx;
  const int height = std::max(map_top + map_h, legend_bottom) + kMarginPx;

  ov.image = detail::blank_image(width, height, kPaper);
  cv::Mat canvas = detail::wrap(ov.image);
  cv::Mat map = canvas(cv::Rect(ov.map_rect.x, ov.map_rect.y, map_w, map_h));
  map.setTo(detail::scalar(kMapBackground));
  for (const Region& r : regions) map(rect_px(ov, r.bounds_m)).setTo(detail::scalar(region_fill(r.split)));
  size_t n_tiles = 0;
  TileLayers acc = collect_tiles(dataset, location, split, ov, &n_tiles);
  draw_map_layers(map, ov, regions, acc);
  draw_scale_and_north(canvas, ov);
  cv::rectangle(canvas, cv::Rect(ov.map_rect.x - 1, ov.map_rect.y - 1, map_w + 2, map_h + 2), detail::scalar(kInk), 1);
  detail::put_text(canvas,
                   strprintf("NuScenesGraph overview: %s, %zu tile(s)%s, %s m/px", location.c_str(), n_tiles,
                             split.empty() ? "" : (" of " + split).c_str(), format_double(ov.m_per_px).c_str()),
                   kMarginPx, kMarginPx + kLineHeightPx - 3);
  ov.legend = detail::legend(&canvas, items, legend_x, map_top, kLegendWidthPx, &legend_bottom);
  ov.crops = std::move(acc.crops);
  return ov;
}

}  // namespace nsg::preview
