#pragma once
// Camera JPEG decoding (docs/nuscenes-input.md) with libjpeg-turbo's scaled decode,
// through its libjpeg API (which can skip rows) with the parameters of its TurboJPEG
// API, so the bytes are tjDecompress2's (tests compare them); the library types stay
// behind a pimpl.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace nsg::nuscenes {

// Decoded size = ceil(full / denominator), as libjpeg's DCT scaling gives.
enum class JpegScale : int { kFull = 1, kHalf = 2, kQuarter = 4 };

// Interleaved 8-bit RGB, row-major, row 0 at the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height * 3
  const std::uint8_t* at(int x, int y) const { return pixels.data() + (static_cast<size_t>(y) * width + x) * 3; }
};

// Size a full-resolution width/height decodes to at `scale`.
int scaled_dimension(int full, JpegScale scale);

// Rows [first, end) of a decoded (scaled) image.
struct RowBand {
  int first = 0;
  int end = 0;
};

// A reusable decoder (one per thread: not thread-safe). Errors name the file.
class JpegDecoder {
 public:
  JpegDecoder();
  ~JpegDecoder();
  JpegDecoder(const JpegDecoder&) = delete;
  JpegDecoder& operator=(const JpegDecoder&) = delete;

  // Decodes the file into `out` (its buffer is reused). Throws IoError if unreadable,
  // ParseError(file, "", ...) on corrupt or truncated data (libjpeg's warnings included).
  void decode_file(const std::filesystem::path& file, JpegScale scale, RgbImage& out);
  RgbImage decode_file(const std::filesystem::path& file, JpegScale scale = JpegScale::kFull);
  // Decodes only the rows `band` of the scaled image (clamped to it) into `out`, sized as
  // the whole image; rows outside the band hold no defined values. The band's bytes are a
  // whole decode's: libjpeg-turbo skips the inverse DCT, upsampling and colour conversion
  // of the rows above and below it, not their entropy decoding, so data that a whole
  // decode rejects is rejected here too, wherever in the file it lies.
  void decode_file_rows(const std::filesystem::path& file, JpegScale scale, RowBand band, RgbImage& out);
  // The same for bytes in memory; `name` is used in error messages.
  void decode_rows(const std::uint8_t* data, size_t size, JpegScale scale, RowBand band, RgbImage& out,
                   const std::string& name);
  // Decodes bytes in memory; `name` is used in error messages.
  void decode(const std::uint8_t* data, size_t size, JpegScale scale, RgbImage& out, const std::string& name);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nsg::nuscenes
