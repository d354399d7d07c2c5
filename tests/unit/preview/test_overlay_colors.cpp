// The graph overlays stand out on every layer: each layer is rendered from a tile holding
// every value its members can take (all 256 LiDAR intensities and semantic ids, headings
// around the circle, all coverage flags, a 16-level RGB cube for the cameras), and each
// overlay colour is checked against every colour that came out (preview.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>
#include <tuple>

#include "nsg/io/dataset.h"
#include "nsg/io/raster.h"
#include "nsg/preview/preview.h"

namespace nsg::test {
namespace {

constexpr int kSide = 64;  // 4096 pixels: every uint8 value 16 times, or one colour of a 16³ cube each

io::Raster raster(int bands, io::SampleType type) {
  io::Raster r;
  r.width = r.height = kSide;
  r.bands = bands;
  r.type = type;
  r.data.assign(r.expected_bytes(), 0);
  return r;
}

void add(io::DatasetTile& tile, const std::string& file, const io::Raster& r) {
  tile.files[file] = io::encode_geotiff(r, io::GeoRef{"boston-seaport", 0.0, 12.8, 0.2});
}

io::DatasetTile every_value_tile() {
  io::DatasetTile tile;
  tile.key = "boston-seaport-test-000000";
  io::Raster lidar = raster(1, io::SampleType::kUInt8), semantic = lidar, coverage = lidar;
  io::Raster rgb = raster(3, io::SampleType::kUInt8), vehicle = raster(1, io::SampleType::kFloat32);
  for (int i = 0; i < kSide * kSide; ++i) {
    lidar.data[i] = semantic.data[i] = static_cast<uint8_t>(i % 256);
    coverage.data[i] = static_cast<uint8_t>(i % 8);
    for (int c = 0; c < 3; ++c) rgb.data[3 * i + c] = static_cast<uint8_t>(17 * ((i >> (4 * c)) & 15));
    // Half the cells a heading around the circle, half none (the dimmed LiDAR shows).
    const float heading = i % 2 ? static_cast<float>(i) / (kSide * kSide) : -1.0f;
    std::memcpy(vehicle.data.data() + 4 * i, &heading, 4);
  }
  add(tile, "lidar.tif", lidar);
  add(tile, "rgb.tif", rgb);
  add(tile, "semantic.tif", semantic);
  add(tile, "vehicle.tif", vehicle);
  add(tile, "coverage.tif", coverage);
  return tile;
}

std::set<std::tuple<int, int, int>> colours_of(const preview::Image& image) {
  std::set<std::tuple<int, int, int>> out;
  for (size_t i = 0; i + 2 < image.rgb.size(); i += 3) out.insert({image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]});
  return out;
}

preview::Rgb rgb_of(const std::tuple<int, int, int>& c) {
  return {static_cast<uint8_t>(std::get<0>(c)), static_cast<uint8_t>(std::get<1>(c)),
          static_cast<uint8_t>(std::get<2>(c))};
}

TEST(OverlayColours, ColourDifferenceKnownValues) {
  EXPECT_NEAR(preview::color_difference({0, 0, 0}, {255, 255, 255}), 100.0, 1e-3);  // L* 0 → 100
  EXPECT_EQ(preview::color_difference({12, 34, 56}, {12, 34, 56}), 0.0);
  // sRGB red is L* 53.24, a* 80.09, b* 67.20 (D65).
  EXPECT_NEAR(preview::color_difference({255, 0, 0}, {0, 0, 0}),
              std::sqrt(53.24 * 53.24 + 80.09 * 80.09 + 67.20 * 67.20), 0.1);
}

TEST(OverlayColours, StandOutOnEveryLayer) {
  const io::DatasetTile tile = every_value_tile();
  const auto& overlays = preview::overlay_colors();
  for (const char* layer : preview::kTileLayerNames) {
    const auto palette = colours_of(preview::render_tile_layer(tile, layer));
    ASSERT_GT(palette.size(), 7u) << layer;
    for (const preview::OverlayColor& o : overlays) {
      double worst = 1e9;
      for (const auto& c : palette) {
        const preview::Rgb p = rgb_of(c);
        // Where the line's colour is near the layer's, its casing is not.
        worst = std::min(worst, std::max(preview::color_difference(o.color, p),
                                         preview::color_difference(preview::kOverlayCasing, p)));
      }
      EXPECT_GE(worst, preview::kOverlayMinContrast) << o.name << " on " << layer;
    }
  }
  // The prediction stands out on the semantic layer by its colour alone (the former orange
  // was 23.5 from the road's and lane markings' colours).
  for (int c = 0; c < preview::kSemanticClassCount; ++c)
    EXPECT_GE(preview::color_difference(preview::kPredEdge, preview::semantic_color(c)), preview::kOverlayMinContrast)
        << preview::semantic_name(c);
  // The overlays differ from their casing and from each other.
  for (size_t a = 0; a < overlays.size(); ++a) {
    EXPECT_GE(preview::color_difference(overlays[a].color, preview::kOverlayCasing), preview::kOverlayMinContrast)
        << overlays[a].name;
    for (size_t b = a + 1; b < overlays.size(); ++b)
      EXPECT_GE(preview::color_difference(overlays[a].color, overlays[b].color), 25.0)
          << overlays[a].name << " vs " << overlays[b].name;
  }
}

}  // namespace
}  // namespace nsg::test
