// Cost of writing one tile's five GeoTIFFs (8 bands) at deflate 1, on tile-like content
// (docs/benchmarks.md budget: ≈ 3 ms per tile). Prints the figure; the bound only catches a
// gross regression (e.g. a level-9 default) on a loaded 2-core machine.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <iostream>

#include "nsg/core/rng.h"
#include "nsg/io/raster.h"

namespace nsg::io {
namespace {

constexpr int kSize = 256;

Raster make(int bands, SampleType type) {
  Raster r;
  r.width = r.height = kSize;
  r.bands = bands;
  r.type = type;
  r.data.assign(r.expected_bytes(), 0);
  return r;
}

// LiDAR intensity on ~60 % of pixels, a noisy camera image, semantic blocks, a few
// vehicles, coverage flags.
std::vector<Raster> tile_set(uint64_t seed) {
  Rng rng(seed);
  Raster lidar = make(1, SampleType::kUInt8), rgb = make(3, SampleType::kUInt8), semantic = make(1, SampleType::kUInt8),
         vehicle = make(1, SampleType::kFloat32), coverage = make(1, SampleType::kUInt8);
  std::vector<float> heading(kSize * kSize, -1.0f);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const size_t i = static_cast<size_t>(y) * kSize + x;
      const bool hit = x + y / 2 < 200 && rng.bernoulli(0.8);
      lidar.data[i] = hit ? static_cast<uint8_t>(1 + rng.uniform_int(uint64_t{120})) : 0;
      for (int b = 0; b < 3; ++b)
        rgb.data[i * 3 + b] = static_cast<uint8_t>(90 + 40 * b + rng.uniform_int(uint64_t{24}));
      semantic.data[i] = static_cast<uint8_t>((x / 40 + y / 64) % 5);
      if ((x / 24) % 4 == 1 && (y / 10) % 6 == 2) heading[i] = 0.25f;
      coverage.data[i] = static_cast<uint8_t>((hit ? 1 : 0) | 2 | 4);
    }
  }
  std::memcpy(vehicle.data.data(), heading.data(), vehicle.data.size());
  return {lidar, rgb, semantic, vehicle, coverage};
}

TEST(GeoTiffTiming, EightBandTileSetAtDeflateOne) {
  const auto rasters = tile_set(7);
  const GeoRef g{"boston-seaport", 500.0, 800.0, 0.2};
  GeoTiffOptions o;
  o.deflate_level = 1;
  size_t total_bytes = 0;
  for (const Raster& r : rasters) total_bytes += encode_geotiff(r, g, o).size();  // warm up
  constexpr int kRepeats = 40;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < kRepeats; ++k)
    for (const Raster& r : rasters) ASSERT_GT(encode_geotiff(r, g, o).size(), 0u);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / kRepeats;
  std::cout << "[ timing ] 8-band tile set (5 GeoTIFFs, 256x256) deflate 1: " << ms << " ms per tile, " << total_bytes
            << " bytes\n";
  RecordProperty("ms_per_tile", std::to_string(ms));
  RecordProperty("bytes_per_tile", std::to_string(total_bytes));
  EXPECT_LT(ms, 60.0);
  EXPECT_LT(total_bytes, size_t{8} * kSize * kSize);  // compression happened
}

}  // namespace
}  // namespace nsg::io
