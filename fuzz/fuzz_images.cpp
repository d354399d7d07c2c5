// The image decoders: GeoTIFF tiles (nsgraph.Dataset, validate), camera JPEGs and PNG
// masks (generate, segment), and a band of a JPEG's rows (the camera stage). The first
// byte picks the decoder. Dimensions are checked on
// the header before any pixel buffer exists (-rss_limit_mb in scripts/fuzz.sh holds them
// to it).
#include <cstdlib>

#include "fuzz_support.h"
#include "nsg/io/raster.h"
#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/semantic_mask.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const uint8_t which = data[0] % 4;
  const std::span<const uint8_t> bytes(data + 1, size - 1);
  nsg::fuzz::expect_only_input_errors([&] {
    if (which == 0) {
      const nsg::io::Raster r = nsg::io::decode_geotiff(bytes, "k.lidar.tif");
      if (r.data.size() != r.expected_bytes() || r.width > 4096 || r.height > 4096) std::abort();
    } else if (which == 1) {
      nsg::nuscenes::JpegDecoder decoder;
      nsg::nuscenes::RgbImage img;
      decoder.decode(bytes.data(), bytes.size(), nsg::nuscenes::JpegScale::kFull, img, "cam.jpg");
      if (img.width > 4096 || img.height > 4096) std::abort();
    } else if (which == 3) {  // a band of rows, as the camera stage decodes (the byte's upper bits place it)
      nsg::nuscenes::JpegDecoder decoder;
      nsg::nuscenes::RgbImage img;
      const int first = (data[0] >> 2) * 7;
      decoder.decode_rows(bytes.data(), bytes.size(), nsg::nuscenes::JpegScale::kHalf, {first, first + 40}, img,
                          "cam.jpg");
      if (img.width > 2048 || img.height > 2048) std::abort();
    } else {
      const nsg::nuscenes::GrayImage m =
          nsg::nuscenes::read_semantic_mask(nsg::fuzz::input_file(bytes.data(), bytes.size()));
      if (m.width > 4096 || m.height > 4096) std::abort();
    }
  });
  return 0;
}
