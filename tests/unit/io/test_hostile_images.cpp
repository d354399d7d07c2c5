// GeoTIFF headers that lie: a 1 KB file claiming 32768 x 32768 pixels is refused from its
// header (nothing the size of the image is allocated); read_geotiff_header reports what a
// header says so readers can check it against the manifest's tile format first.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/io/raster.h"

namespace nsg::io {
namespace {

// A little-endian striped TIFF (one strip, uncompressed) whose header claims
// width x height x bands uint8 pixels but carries only `data_bytes` of data.
std::vector<uint8_t> lying_tiff(uint32_t width, uint32_t height, uint16_t bands, uint32_t data_bytes) {
  struct Entry {
    uint16_t tag, type;
    uint32_t count, value;
  };
  const uint16_t kShort = 3, kLong = 4;
  const std::vector<Entry> entries = {
      {256, kLong, 1, width},  {257, kLong, 1, height}, {258, kShort, 1, 8},
      {259, kShort, 1, 1},     {262, kShort, 1, 1},     {273, kLong, 1, 0},
      {277, kShort, 1, bands}, {278, kLong, 1, height}, {279, kLong, 1, width * height * bands}};
  std::vector<uint8_t> out = {'I', 'I', 42, 0, 8, 0, 0, 0};
  const auto put = [&](uint32_t v, int n) {
    for (int k = 0; k < n; ++k) out.push_back(static_cast<uint8_t>(v >> (8 * k)));
  };
  const uint32_t data_at = 8 + 2 + 12 * static_cast<uint32_t>(entries.size()) + 4;
  put(static_cast<uint32_t>(entries.size()), 2);
  for (const Entry& e : entries) {
    put(e.tag, 2);
    put(e.type, 2);
    put(e.count, 4);
    put(e.tag == 273 ? data_at : e.value, e.type == kShort ? 2 : 4);
    if (e.type == kShort) put(0, 2);
  }
  put(0, 4);  // no next IFD
  out.resize(out.size() + data_bytes, 7);
  return out;
}

TEST(HostileGeoTiff, HugeDimensionsAreRefusedFromTheHeader) {
  const std::vector<uint8_t> tiff = lying_tiff(32768, 32768, 1, 1024);
  const RasterHeader h = read_geotiff_header(tiff, "k-test-000000.lidar.tif");
  EXPECT_EQ(h.width, 32768);
  EXPECT_EQ(h.height, 32768);
  try {
    decode_geotiff(tiff, "k-test-000000.lidar.tif");
    FAIL() << "decoded";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("k-test-000000.lidar.tif"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("32768 x 32768"), std::string::npos) << e.what();
  }
}

TEST(HostileGeoTiff, HeaderIsCheckedAgainstTheTileFormat) {
  const std::vector<uint8_t> tiff = lying_tiff(256, 256, 1, 256 * 256);
  const RasterHeader rgb{256, 256, 3, SampleType::kUInt8};
  try {
    check_raster_header(read_geotiff_header(tiff, "k.rgb.tif"), rgb, "k.rgb.tif", "shard test-000000");
    FAIL() << "a 1-band raster passed as rgb";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("256 x 256 uint8 x 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("got 256 x 256 uint8 x 1"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(check_raster_header(read_geotiff_header(tiff, "k.lidar.tif"), {256, 256, 1, SampleType::kUInt8},
                                      "k.lidar.tif", ""));
  const Raster r = decode_geotiff(tiff, "k.lidar.tif");
  EXPECT_EQ(r.data.size(), 256u * 256u);
}

}  // namespace
}  // namespace nsg::io
