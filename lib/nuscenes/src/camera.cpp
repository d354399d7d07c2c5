#include "nsg/nuscenes/camera.h"

// jpeglib.h needs FILE and size_t declared first.
#include <csetjmp>
#include <cstdio>
#include <jpeglib.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "nsg/core/error.h"
#include "nsg/core/files.h"

namespace nsg::nuscenes {
namespace {
// nuScenes cameras are 1600 x 900; the header is checked before any pixel buffer is
// allocated, so a small file claiming a huge image costs nothing.
constexpr int kMaxJpegSidePx = 4096;

// Whether the full size a header claims is a camera image's (checked before any pixel
// buffer is allocated), and the error when it is not.
bool is_camera_size(int width, int height) {
  return width > 0 && height > 0 && width <= kMaxJpegSidePx && height <= kMaxJpegSidePx;
}
ParseError camera_size_error(const std::string& name, int width, int height) {
  return ParseError(name, "JPEG header",
                    "a camera image of at most " + std::to_string(kMaxJpegSidePx) + " x " +
                        std::to_string(kMaxJpegSidePx) + " pixels, got " + std::to_string(width) + " x " +
                        std::to_string(height));
}

// libjpeg reports an error through error_exit, which must not return: it jumps back to
// the setjmp of the call in progress, which returns false (no exception crosses C frames;
// the functions holding a setjmp have only trivially destructible locals). Warnings
// (corrupt data the library would guess around, a premature end) are errors too, as
// TurboJPEG's TJFLAG_STOPONWARNING makes them: a partial image is not data.
struct JpegErrors {
  jpeg_error_mgr mgr;  // first: libjpeg sees a jpeg_error_mgr*
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void on_jpeg_error(j_common_ptr info) {
  auto* errors = reinterpret_cast<JpegErrors*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->jump, 1);
}

void on_jpeg_message(j_common_ptr info, int level) {
  if (level < 0) on_jpeg_error(info);  // a warning; levels ≥ 0 are traces
}

// The decoder's libjpeg state, kept from image to image.
struct Decompressor {
  jpeg_decompress_struct info{};
  JpegErrors errors{};
  bool created = false;
};

bool create_decompressor(Decompressor& d) {
  d.info.err = jpeg_std_error(&d.errors.mgr);
  d.errors.mgr.error_exit = on_jpeg_error;
  d.errors.mgr.emit_message = on_jpeg_message;
  if (setjmp(d.errors.jump)) return false;
  jpeg_create_decompress(&d.info);
  d.created = true;
  return true;
}

// Reads the header of `data` and sets the decode's parameters (TurboJPEG's tjDecompress2
// for TJPF_RGB, so the bytes are its: RGB out, the accurate integer DCT, fancy
// upsampling) at 1/denom. Fills the full and scaled sizes.
bool read_header(Decompressor& d, const std::uint8_t* data, size_t size, int denom, int& full_w, int& full_h,
                 int& out_w, int& out_h) {
  if (setjmp(d.errors.jump)) return false;
  jpeg_mem_src(&d.info, data, static_cast<unsigned long>(size));
  jpeg_read_header(&d.info, TRUE);
  d.info.out_color_space = JCS_EXT_RGB;
  d.info.dct_method = JDCT_ISLOW;
  d.info.do_fancy_upsampling = TRUE;
  d.info.scale_num = 1;
  d.info.scale_denom = static_cast<unsigned int>(denom);
  jpeg_calc_output_dimensions(&d.info);
  full_w = static_cast<int>(d.info.image_width);
  full_h = static_cast<int>(d.info.image_height);
  out_w = static_cast<int>(d.info.output_width);
  out_h = static_cast<int>(d.info.output_height);
  return true;
}

// Decodes rows [first, end) (0 ≤ first ≤ end ≤ height, first < height) into `pixels`
// (out_w × height × 3). The rows below the band are skipped up to the last one, which is
// decoded: skipping to the very end would leave their entropy-coded data unread, and a
// corrupt tail unnoticed.
bool decode_band(Decompressor& d, std::uint8_t* pixels, int first, int end) {
  if (setjmp(d.errors.jump)) return false;
  jpeg_start_decompress(&d.info);
  const size_t stride = static_cast<size_t>(d.info.output_width) * 3;
  const auto height = static_cast<JDIMENSION>(d.info.output_height);
  if (first > 0) jpeg_skip_scanlines(&d.info, static_cast<JDIMENSION>(first));
  const auto read_rows = [&](JDIMENSION stop) {
    JSAMPROW rows[16];  // a few rows a call: one row a call costs more than the decode
    while (d.info.output_scanline < stop) {
      JDIMENSION n = 0;
      for (; n < 16 && d.info.output_scanline + n < stop; ++n) rows[n] = pixels + (d.info.output_scanline + n) * stride;
      jpeg_read_scanlines(&d.info, rows, n);
    }
  };
  read_rows(static_cast<JDIMENSION>(end));
  if (d.info.output_scanline + 1 < height) jpeg_skip_scanlines(&d.info, height - 1 - d.info.output_scanline);
  read_rows(height);
  jpeg_finish_decompress(&d.info);
  return true;
}

}  // namespace

struct JpegDecoder::Impl {
  Decompressor state;
  ~Impl() {
    if (state.created) jpeg_destroy_decompress(&state.info);
  }
  // The libjpeg state, created on first use.
  Decompressor& decoder() {
    if (!state.created && !create_decompressor(state))
      throw InternalError("", "", std::string("jpeg_create_decompress failed: ") + state.errors.message);
    return state;
  }
};

int scaled_dimension(int full, JpegScale scale) {
  // ceil(full / denom), as libjpeg's jdiv_round_up sizes a scaled decode.
  const int64_t denom = static_cast<int>(scale);
  return static_cast<int>((static_cast<int64_t>(full) + denom - 1) / denom);
}

JpegDecoder::JpegDecoder() : impl_(std::make_unique<Impl>()) {}

JpegDecoder::~JpegDecoder() = default;

void JpegDecoder::decode(const std::uint8_t* data, size_t size, JpegScale scale, RgbImage& out,
                         const std::string& name) {
  decode_rows(data, size, scale, {0, std::numeric_limits<int>::max()}, out, name);
}

void JpegDecoder::decode_file(const std::filesystem::path& file, JpegScale scale, RgbImage& out) {
  const std::string bytes = read_file(file);
  decode(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), scale, out, file.string());
}

void JpegDecoder::decode_file_rows(const std::filesystem::path& file, JpegScale scale, RowBand band, RgbImage& out) {
  const std::string bytes = read_file(file);
  decode_rows(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), scale, band, out, file.string());
}

void JpegDecoder::decode_rows(const std::uint8_t* data, size_t size, JpegScale scale, RowBand band, RgbImage& out,
                              const std::string& name) {
  Decompressor& d = impl_->decoder();
  const auto fail = [&](const char* what) {
    jpeg_abort_decompress(&d.info);  // back to a state that takes the next image
    return ParseError(name, "", std::string("a valid JPEG image (") + what + ": " + d.errors.message + ")");
  };
  if (size == 0) throw ParseError(name, "", "a valid JPEG image (header: the file is empty)");
  int full_w = 0, full_h = 0, width = 0, height = 0;
  if (!read_header(d, data, size, static_cast<int>(scale), full_w, full_h, width, height)) throw fail("header");
  if (!is_camera_size(full_w, full_h)) {
    jpeg_abort_decompress(&d.info);  // as fail(): the decoder takes the next image
    throw camera_size_error(name, full_w, full_h);
  }
  out.width = width;
  out.height = height;
  out.pixels.resize(static_cast<size_t>(out.width) * out.height * 3);
  int first = std::clamp(band.first, 0, out.height), end = std::clamp(band.end, first, out.height);
  if (first == end) first = end = 0;  // no rows wanted: the data is still checked
  if (!decode_band(d, out.pixels.data(), first, end)) throw fail("decode");
}

RgbImage JpegDecoder::decode_file(const std::filesystem::path& file, JpegScale scale) {
  RgbImage out;
  decode_file(file, scale, out);
  return out;
}

}  // namespace nsg::nuscenes
