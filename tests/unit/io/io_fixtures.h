#pragma once
// Rasters with known content for the io tests.
#include <cstdint>
#include <vector>

#include "nsg/io/raster.h"

namespace nsg::io::test {

// uint8 pattern that differs per pixel and band, so a swapped row or band shows.
inline Raster pattern_u8(int width, int height, int bands) {
  Raster r;
  r.width = width;
  r.height = height;
  r.bands = bands;
  r.type = SampleType::kUInt8;
  r.data.resize(r.expected_bytes());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int b = 0; b < bands; ++b)
        r.data[(static_cast<size_t>(y) * width + x) * bands + b] =
            static_cast<uint8_t>((x * 7 + y * 13 + b * 101) & 0xff);
  return r;
}

// float32 "vehicle" layer: −1 background, headings in [0, 1) in a square.
inline Raster pattern_f32(int width, int height) {
  Raster r;
  r.width = width;
  r.height = height;
  r.type = SampleType::kFloat32;
  std::vector<float> v(static_cast<size_t>(width) * height, -1.0f);
  for (int y = height / 4; y < height / 2; ++y)
    for (int x = width / 4; x < width / 2; ++x) v[static_cast<size_t>(y) * width + x] = (x % 100) / 100.0f;
  const auto* bytes = reinterpret_cast<const uint8_t*>(v.data());
  r.data.assign(bytes, bytes + v.size() * sizeof(float));
  return r;
}

}  // namespace nsg::io::test
