// JPEG and PNG encoder tests: header bytes like the real nuScenes JPEGs, decodable output,
// PNG round trip and deterministic bytes.
#include <gtest/gtest.h>
#include <png.h>
#include <turbojpeg.h>

#include <cstring>

#include "nsg/core/error.h"
#include "nsg/synth/image_encode.h"

namespace nsg::synth {
namespace {

CameraImage gradient_image(int w, int h) {
  CameraImage image;
  image.width_px = w;
  image.height_px = h;
  image.rgb.resize(static_cast<size_t>(w) * h * 3);
  image.classes.resize(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      image.rgb[3 * i] = static_cast<uint8_t>(x * 255 / w);
      image.rgb[3 * i + 1] = static_cast<uint8_t>(y * 255 / h);
      image.rgb[3 * i + 2] = 128;
      image.classes[i] = static_cast<uint8_t>((x / 16 + y / 16) % 14);
    }
  image.classes[5] = 255;  // void survives
  return image;
}

// Offset of the first marker 0xFF `code` before the scan data, or npos.
size_t find_marker(const std::vector<uint8_t>& jpg, uint8_t code) {
  size_t pos = 2;  // after SOI
  while (pos + 4 <= jpg.size() && jpg[pos] == 0xFF) {
    const uint8_t m = jpg[pos + 1];
    if (m == code) return pos;
    if (m == 0xDA) break;  // start of scan
    pos += 2 + (static_cast<size_t>(jpg[pos + 2]) << 8 | jpg[pos + 3]);
  }
  return std::string::npos;
}

TEST(ImageEncode, JpegHasJfif101HeaderBaselineAnd420) {
  const CameraImage image = gradient_image(1600, 900);
  const std::vector<uint8_t> jpg = encode_jpeg(image);
  ASSERT_GT(jpg.size(), 100u);
  // SOI, then APP0 "JFIF\0" version 1.01, units 0, density 1:1, no thumbnail.
  const uint8_t head[] = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x10, 'J',  'F',  'I',  'F',
                          0x00, 0x01, 0x01, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0x00};
  ASSERT_EQ(std::memcmp(jpg.data(), head, sizeof(head)), 0);
  EXPECT_EQ(find_marker(jpg, 0xE1), std::string::npos) << "no EXIF";
  EXPECT_EQ(find_marker(jpg, 0xC2), std::string::npos) << "not progressive";
  const size_t sof = find_marker(jpg, 0xC0);
  ASSERT_NE(sof, std::string::npos) << "baseline SOF0";
  const uint8_t* f = &jpg[sof + 4];
  EXPECT_EQ(f[0], 8);                 // precision
  EXPECT_EQ(f[1] << 8 | f[2], 900);   // height
  EXPECT_EQ(f[3] << 8 | f[4], 1600);  // width
  ASSERT_EQ(f[5], 3);                 // components
  EXPECT_EQ(f[7], 0x22);              // Y: 2x2 → 4:2:0
  EXPECT_EQ(f[10], 0x11);             // Cb
  EXPECT_EQ(f[13], 0x11);             // Cr
  // libjpeg quality 80 scales the standard tables by 40 %: luma DC 16 → 6.
  const size_t dqt = find_marker(jpg, 0xDB);
  ASSERT_NE(dqt, std::string::npos);
  EXPECT_EQ(jpg[dqt + 4], 0x00);  // 8-bit table 0
  EXPECT_EQ(jpg[dqt + 5], 6);
  EXPECT_EQ(jpg[jpg.size() - 2], 0xFF);
  EXPECT_EQ(jpg[jpg.size() - 1], 0xD9);

  tjhandle tj = tjInitDecompress();
  int w = 0, h = 0, subsamp = -1, colorspace = -1;
  ASSERT_EQ(tjDecompressHeader3(tj, jpg.data(), jpg.size(), &w, &h, &subsamp, &colorspace), 0);
  EXPECT_EQ(w, 1600);
  EXPECT_EQ(h, 900);
  EXPECT_EQ(subsamp, TJSAMP_420);
  std::vector<uint8_t> decoded(static_cast<size_t>(w) * h * 3);
  ASSERT_EQ(tjDecompress2(tj, jpg.data(), jpg.size(), decoded.data(), w, 0, h, TJPF_RGB, 0), 0);
  tjDestroy(tj);
  double abs_sum = 0;
  for (size_t i = 0; i < decoded.size(); ++i) abs_sum += std::abs(int{decoded[i]} - int{image.rgb[i]});
  EXPECT_LT(abs_sum / decoded.size(), 3.0);
  EXPECT_EQ(encode_jpeg(image), jpg) << "deterministic";
}

std::vector<uint8_t> decode_png_gray(const std::vector<uint8_t>& png, int& w, int& h) {
  png_image img;
  std::memset(&img, 0, sizeof(img));
  img.version = PNG_IMAGE_VERSION;
  EXPECT_TRUE(png_image_begin_read_from_memory(&img, png.data(), png.size()));
  img.format = PNG_FORMAT_GRAY;
  w = static_cast<int>(img.width);
  h = static_cast<int>(img.height);
  std::vector<uint8_t> out(PNG_IMAGE_SIZE(img));
  EXPECT_TRUE(png_image_finish_read(&img, nullptr, out.data(), 0, nullptr));
  return out;
}

TEST(ImageEncode, PngGray8RoundTripAndFixedBytes) {
  const CameraImage image = gradient_image(333, 77);
  const std::vector<uint8_t> png = encode_png_gray8_from(image);
  const uint8_t sig[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  ASSERT_EQ(std::memcmp(png.data(), sig, 8), 0);
  ASSERT_EQ(std::memcmp(&png[12], "IHDR", 4), 0);
  EXPECT_EQ(png[24], 8);  // bit depth
  EXPECT_EQ(png[25], 0);  // colour type gray
  const std::string bytes(png.begin(), png.end());
  EXPECT_EQ(bytes.find("tIME"), std::string::npos);
  EXPECT_EQ(bytes.find("tEXt"), std::string::npos);
  int w = 0, h = 0;
  const std::vector<uint8_t> decoded = decode_png_gray(png, w, h);
  EXPECT_EQ(w, 333);
  EXPECT_EQ(h, 77);
  EXPECT_EQ(decoded, image.classes);
  EXPECT_EQ(encode_png_gray8(image.classes.data(), 333, 77), png);
}

TEST(ImageEncode, RejectsBadInput) {
  CameraImage image = gradient_image(16, 8);
  EXPECT_THROW(encode_jpeg(image, 0), ConfigError);
  EXPECT_THROW(encode_jpeg(image, 101), ConfigError);
  image.rgb.pop_back();
  EXPECT_THROW(encode_jpeg(image), ConfigError);
  image.classes.pop_back();
  EXPECT_THROW(encode_png_gray8_from(image), ConfigError);
  EXPECT_THROW(encode_png_gray8(nullptr, 4, 4), ConfigError);
  const uint8_t px[4] = {0, 1, 2, 3};
  EXPECT_THROW(encode_png_gray8(px, 0, 4), ConfigError);
  EXPECT_THROW(encode_jpeg(CameraImage{}), ConfigError);
}

}  // namespace
}  // namespace nsg::synth
