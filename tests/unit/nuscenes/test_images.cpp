// Camera JPEG scaled decode (test images written with turbojpeg here) and the 8-bit
// semantic-mask PNG reader (test images written with libpng here).
#include <gtest/gtest.h>
#include <png.h>
#include <turbojpeg.h>

#include <cstdio>

#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "nuscenes_fixture.h"

namespace nsg::nuscenes {
namespace {

// A width×height JPEG: left half red, right half blue; quality 95, 4:2:0 like nuScenes.
std::string encode_test_jpeg(int width, int height) {
  std::vector<unsigned char> rgb(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      unsigned char* p = &rgb[(static_cast<size_t>(y) * width + x) * 3];
      p[0] = x < width / 2 ? 255 : 0;
      p[1] = 0;
      p[2] = x < width / 2 ? 0 : 255;
    }
  }
  tjhandle h = tjInitCompress();
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  const int rc = tjCompress2(h, rgb.data(), width, 0, height, TJPF_RGB, &jpeg, &size, TJSAMP_420, 95, 0);
  std::string out = rc == 0 ? std::string(reinterpret_cast<char*>(jpeg), size) : std::string();
  tjFree(jpeg);
  tjDestroy(h);
  return out;
}

TEST(Jpeg, ScaledSizes) {
  EXPECT_EQ(scaled_dimension(1600, JpegScale::kFull), 1600);
  EXPECT_EQ(scaled_dimension(1600, JpegScale::kHalf), 800);
  EXPECT_EQ(scaled_dimension(900, JpegScale::kQuarter), 225);
  EXPECT_EQ(scaled_dimension(101, JpegScale::kHalf), 51);  // rounds up
  EXPECT_EQ(scaled_dimension(61, JpegScale::kQuarter), 16);
}

TEST(Jpeg, DecodesAtEachScaleWithOneDecoder) {
  test::TempDir dir("jpeg");
  const std::string jpeg = encode_test_jpeg(160, 90);
  ASSERT_FALSE(jpeg.empty());
  test::write_text(dir / "cam.jpg", jpeg);
  JpegDecoder decoder;
  RgbImage image;
  const struct {
    JpegScale scale;
    int w, h;
  } cases[] = {{JpegScale::kFull, 160, 90}, {JpegScale::kHalf, 80, 45}, {JpegScale::kQuarter, 40, 23}};
  for (const auto& c : cases) {
    decoder.decode_file(dir / "cam.jpg", c.scale, image);
    EXPECT_EQ(image.width, c.w);
    EXPECT_EQ(image.height, c.h);
    ASSERT_EQ(image.pixels.size(), static_cast<size_t>(c.w) * c.h * 3);
    // Far from the colour edge: red on the left, blue on the right (JPEG is lossy).
    const std::uint8_t* left = image.at(c.w / 8, c.h / 2);
    const std::uint8_t* right = image.at(c.w - 1 - c.w / 8, c.h / 2);
    EXPECT_GT(left[0], 230);
    EXPECT_LT(left[2], 30);
    EXPECT_LT(right[0], 30);
    EXPECT_GT(right[2], 230);
  }
}

TEST(Jpeg, OddSizeRoundsUp) {
  test::TempDir dir("jpeg");
  test::write_text(dir / "odd.jpg", encode_test_jpeg(101, 61));
  JpegDecoder decoder;
  const RgbImage half = decoder.decode_file(dir / "odd.jpg", JpegScale::kHalf);
  EXPECT_EQ(half.width, 51);
  EXPECT_EQ(half.height, 31);
}

TEST(Jpeg, CorruptDataNamesTheFile) {
  test::TempDir dir("jpeg");
  const std::string jpeg = encode_test_jpeg(64, 48);
  test::write_text(dir / "truncated.jpg", jpeg.substr(0, jpeg.size() / 2));
  test::write_text(dir / "garbage.jpg", "this is not a jpeg at all");
  JpegDecoder decoder;
  test::expect_error<ParseError>([&] { decoder.decode_file(dir / "truncated.jpg"); }, "truncated.jpg", {"JPEG"});
  test::expect_error<ParseError>([&] { decoder.decode_file(dir / "garbage.jpg"); }, "garbage.jpg", {"JPEG"});
  test::expect_error<IoError>([&] { decoder.decode_file(dir / "missing.jpg"); }, "missing.jpg", {});
  // The decoder stays usable after an error.
  test::write_text(dir / "ok.jpg", jpeg);
  EXPECT_EQ(decoder.decode_file(dir / "ok.jpg", JpegScale::kQuarter).width, 16);
}

// A width×height JPEG of a busy pattern (every 8×8 block different, chroma too), 4:2:0
// like nuScenes: every band must match TurboJPEG's whole decode byte for byte, fancy
// upsampling across the band's edges included.
std::string encode_textured_jpeg(int width, int height) {
  std::vector<unsigned char> rgb(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int k = 0; k < 3; ++k)
        rgb[(static_cast<size_t>(y) * width + x) * 3 + k] =
            static_cast<unsigned char>((x * (7 + k) + y * (13 - k) + x * y / (3 + k)) % 256);
  tjhandle h = tjInitCompress();
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  const int rc = tjCompress2(h, rgb.data(), width, 0, height, TJPF_RGB, &jpeg, &size, TJSAMP_420, 85, 0);
  std::string out = rc == 0 ? std::string(reinterpret_cast<char*>(jpeg), size) : std::string();
  tjFree(jpeg);
  tjDestroy(h);
  return out;
}

// The reference decode: TurboJPEG's tjDecompress2 of the whole image (RGB, warnings as
// errors), which JpegDecoder's bytes must equal. An empty image when it refuses the data.
RgbImage turbojpeg_decode(const std::filesystem::path& file, JpegScale scale) {
  const std::string bytes = test::read_text(file);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  RgbImage out;
  tjhandle h = tjInitDecompress();
  int w = 0, ht = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(h, data, bytes.size(), &w, &ht, &subsampling, &colorspace) == 0) {
    const tjscalingfactor factor{1, static_cast<int>(scale)};
    out.width = TJSCALED(w, factor);
    out.height = TJSCALED(ht, factor);
    out.pixels.resize(static_cast<size_t>(out.width) * out.height * 3);
    if (tjDecompress2(h, data, bytes.size(), out.pixels.data(), out.width, 0, out.height, TJPF_RGB,
                      TJFLAG_STOPONWARNING) != 0)
      out = RgbImage{};
  }
  tjDestroy(h);
  return out;
}

// Rows [first, end) of `band` equal those of `whole` (same size).
void expect_band_rows(const RgbImage& whole, const RgbImage& band, RowBand rows, const std::string& what) {
  ASSERT_EQ(band.width, whole.width) << what;
  ASSERT_EQ(band.height, whole.height) << what;
  const size_t stride = static_cast<size_t>(whole.width) * 3;
  for (int y = rows.first; y < rows.end; ++y)
    ASSERT_TRUE(std::equal(whole.at(0, y), whole.at(0, y) + stride, band.at(0, y))) << what << ": row " << y;
}

TEST(Jpeg, WholeAndBandsEqualTurboJpegAtEachScale) {
  test::TempDir dir("jpeg");
  const std::string jpeg = encode_textured_jpeg(203, 157);  // odd sizes: partial MCUs at the edges
  ASSERT_FALSE(jpeg.empty());
  test::write_text(dir / "busy.jpg", jpeg);
  JpegDecoder decoder;
  RgbImage band;
  for (JpegScale scale : {JpegScale::kFull, JpegScale::kHalf, JpegScale::kQuarter}) {
    const RgbImage whole = turbojpeg_decode(dir / "busy.jpg", scale);
    const int h = whole.height;
    ASSERT_GT(h, 0);
    expect_band_rows(whole, decoder.decode_file(dir / "busy.jpg", scale), {0, h},
                     "whole image at 1/" + std::to_string(static_cast<int>(scale)));
    // Bands starting and ending inside and on iMCU rows, one row, the whole image.
    for (const RowBand rows : {RowBand{0, h}, RowBand{0, 1}, RowBand{h - 1, h}, RowBand{1, 2}, RowBand{7, 9},
                               RowBand{8, 16}, RowBand{h / 2, h}, RowBand{h / 3, 2 * h / 3}, RowBand{15, h - 3}}) {
      decoder.decode_file_rows(dir / "busy.jpg", scale, rows, band);
      expect_band_rows(whole, band, rows,
                       "scale 1/" + std::to_string(static_cast<int>(scale)) + " rows " + std::to_string(rows.first) +
                           "–" + std::to_string(rows.end));
    }
  }
}

TEST(Jpeg, WholeAndBandsEqualTurboJpegOnTheRealKeyFrame) {
  const std::filesystem::path samples =
      test::source_dir() / "tests" / "data" / "real" / "scene-0061-keyframe" / "samples";
  JpegDecoder decoder;
  RgbImage band;
  size_t images = 0;
  for (const auto& dir : std::filesystem::directory_iterator(samples)) {
    if (dir.path().filename().string().rfind("CAM_", 0) != 0) continue;
    for (const auto& f : std::filesystem::directory_iterator(dir.path())) {
      // The whole image at full size (what `segment` reads) and at ½ (what the stage reads).
      const RgbImage full = turbojpeg_decode(f.path(), JpegScale::kFull);
      expect_band_rows(full, decoder.decode_file(f.path(), JpegScale::kFull), {0, full.height},
                       f.path().filename().string() + " whole, full size");
      const RgbImage whole = turbojpeg_decode(f.path(), JpegScale::kHalf);
      expect_band_rows(whole, decoder.decode_file(f.path(), JpegScale::kHalf), {0, whole.height},
                       f.path().filename().string() + " whole, ½");
      const RowBand rows{whole.height / 2 - 5, whole.height - 40};  // below the horizon, as the camera stage asks
      decoder.decode_file_rows(f.path(), JpegScale::kHalf, rows, band);
      expect_band_rows(whole, band, rows, f.path().filename().string());
      ++images;
    }
  }
  EXPECT_EQ(images, 6u);
}

TEST(Jpeg, BandRejectsWhatTurboJpegRejects) {
  test::TempDir dir("jpeg");
  const std::string jpeg = encode_textured_jpeg(64, 480);
  // Cut in the lower part of the image: a band of the top rows does not need those rows,
  // but their data is still read, so the damage is found as a whole decode finds it.
  test::write_text(dir / "truncated.jpg", jpeg.substr(0, jpeg.size() * 3 / 4));
  test::write_text(dir / "garbage.jpg", "this is not a jpeg at all");
  test::write_text(dir / "empty.jpg", "");
  JpegDecoder decoder;
  RgbImage image;
  EXPECT_TRUE(turbojpeg_decode(dir / "truncated.jpg", JpegScale::kHalf).pixels.empty());  // the reference refuses it
  test::expect_error<ParseError>([&] { decoder.decode_file(dir / "truncated.jpg"); }, "truncated.jpg", {"JPEG"});
  for (const RowBand rows : {RowBand{0, 8}, RowBand{100, 120}, RowBand{5, 5}, RowBand{240, 240}})
    test::expect_error<ParseError>(
        [&] { decoder.decode_file_rows(dir / "truncated.jpg", JpegScale::kHalf, rows, image); }, "truncated.jpg",
        {"a valid JPEG image (decode: "});
  test::expect_error<ParseError>(
      [&] {
        decoder.decode_file_rows(dir / "garbage.jpg", JpegScale::kHalf, {0, 10}, image);
      },
      "garbage.jpg", {"JPEG", "header"});
  test::expect_error<ParseError>(
      [&] {
        decoder.decode_file_rows(dir / "empty.jpg", JpegScale::kHalf, {0, 10}, image);
      },
      "empty.jpg", {"JPEG"});
  test::expect_error<IoError>(
      [&] {
        decoder.decode_file_rows(dir / "missing.jpg", JpegScale::kHalf, {0, 10}, image);
      },
      "missing.jpg", {});
  // The decoder stays usable after each error.
  test::write_text(dir / "ok.jpg", jpeg);
  decoder.decode_file_rows(dir / "ok.jpg", JpegScale::kHalf, {10, 20}, image);
  EXPECT_EQ(image.width, 32);
  EXPECT_EQ(image.height, 240);
}

// Writes an 8-bit PNG with the simplified libpng API; format PNG_FORMAT_GRAY or _RGB.
void write_png(const std::filesystem::path& file, int width, int height, png_uint_32 format,
               const std::vector<std::uint8_t>& pixels) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = format;
  ASSERT_NE(png_image_write_to_file(&image, file.c_str(), 0, pixels.data(), 0, nullptr), 0) << image.message;
}

TEST(SemanticMask, ReadsGray8ClassIds) {
  test::TempDir dir("png");
  write_png(dir / "mask.png", 3, 2, PNG_FORMAT_GRAY, {0, 1, 2, 7, 255, 13});
  const GrayImage mask = read_semantic_mask(dir / "mask.png");
  EXPECT_EQ(mask.width, 3);
  EXPECT_EQ(mask.height, 2);
  EXPECT_EQ(mask.at(2, 0), 2);
  EXPECT_EQ(mask.at(0, 1), 7);
  EXPECT_EQ(mask.at(1, 1), 255);
}

TEST(SemanticMask, ReadsTheFixtureSemanticPrior) {
  const GrayImage prior = read_semantic_mask(test::fixture_root() / "maps" / (test::kMap + ".png"));
  EXPECT_EQ(prior.width, 4);
  EXPECT_EQ(prior.height, 3);
  EXPECT_EQ(prior.at(1, 0), 255);
  EXPECT_EQ(prior.at(3, 2), 255);
  EXPECT_EQ(prior.at(0, 2), 0);
}

TEST(SemanticMask, RejectsRgbAndNonPng) {
  test::TempDir dir("png");
  write_png(dir / "rgb.png", 2, 2, PNG_FORMAT_RGB, std::vector<std::uint8_t>(12, 9));
  test::expect_error<ParseError>([&] { read_semantic_mask(dir / "rgb.png"); }, "rgb.png", {"8-bit single-channel"});
  test::write_text(dir / "text.png", "not a png file");
  test::expect_error<ParseError>([&] { read_semantic_mask(dir / "text.png"); }, "text.png", {"PNG"});
  write_png(dir / "cut.png", 64, 64, PNG_FORMAT_GRAY, std::vector<std::uint8_t>(64 * 64, 3));
  const std::string bytes = test::read_text(dir / "cut.png");
  test::write_text(dir / "cut.png", bytes.substr(0, bytes.size() - 30));
  test::expect_error<ParseError>([&] { read_semantic_mask(dir / "cut.png"); }, "cut.png", {});
}

// Big-endian bytes of v at s[at..at+n).
void put_be(std::string& s, size_t at, uint32_t v, int n) {
  for (int k = 0; k < n; ++k) s[at + k] = static_cast<char>((v >> (8 * (n - 1 - k))) & 0xff);
}

uint32_t crc32_of(const std::string& s, size_t at, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = at; i < at + n; ++i) {
    c ^= static_cast<unsigned char>(s[i]);
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

TEST(Jpeg, HeaderClaimingAHugeImageIsRefusedBeforeDecoding) {
  test::TempDir dir("jpeg-huge");
  std::string jpeg = encode_test_jpeg(16, 16);
  const size_t sof = jpeg.find("\xff\xc0");
  ASSERT_NE(sof, std::string::npos);
  put_be(jpeg, sof + 5, 65000, 2);  // height
  put_be(jpeg, sof + 7, 65000, 2);  // width
  test::write_text(dir / "huge.jpg", jpeg);
  JpegDecoder decoder;
  test::expect_error<ParseError>([&] { decoder.decode_file(dir / "huge.jpg", JpegScale::kFull); }, "huge.jpg",
                                 {"at most 4096 x 4096", "65000 x 65000"});
  // A band is refused the same way before allocating, and `image` is left as it was.
  RgbImage image;
  test::expect_error<ParseError>(
      [&] {
        decoder.decode_file_rows(dir / "huge.jpg", JpegScale::kHalf, {0, 10}, image);
      },
      "huge.jpg", {"at most 4096 x 4096", "65000 x 65000"});
  EXPECT_EQ(image.width, 0);
  EXPECT_TRUE(image.pixels.empty());
  // ...and takes the next image.
  test::write_text(dir / "ok.jpg", encode_test_jpeg(16, 16));
  decoder.decode_file_rows(dir / "ok.jpg", JpegScale::kHalf, {0, 8}, image);
  EXPECT_EQ(image.width, 8);
}

TEST(SemanticMask, HeaderClaimingAHugeMaskIsRefusedBeforeReading) {
  test::TempDir dir("png-huge");
  write_png(dir / "mask.png", 2, 2, PNG_FORMAT_GRAY, {0, 1, 2, 3});
  std::string png = test::read_text(dir / "mask.png");
  // IHDR: length (8), "IHDR" (12), width (16), height (20), ..., CRC over type + data (29).
  put_be(png, 16, 100000, 4);
  put_be(png, 20, 100000, 4);
  put_be(png, 29, crc32_of(png, 12, 17), 4);
  test::write_text(dir / "huge.png", png);
  test::expect_error<ParseError>([&] { read_semantic_mask(dir / "huge.png"); }, "huge.png",
                                 {"at most", "100000 x 100000"});
}

}  // namespace
}  // namespace nsg::nuscenes
