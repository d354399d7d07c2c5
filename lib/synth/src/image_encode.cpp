// JPEG (libturbojpeg) and gray PNG (libpng) encoders with deterministic output.
#include "nsg/synth/image_encode.h"

#include <png.h>
#include <turbojpeg.h>

#include <csetjmp>
#include <cstring>
#include <string>

#include "nsg/core/error.h"

namespace nsg::synth {
namespace {

void check_size(int width_px, int height_px, const char* what) {
  if (width_px <= 0 || height_px <= 0 || width_px > 65500 || height_px > 65500) {
    throw ConfigError(
        "", what, "an image size in 1..65500 px, got " + std::to_string(width_px) + "x" + std::to_string(height_px));
  }
}

// libpng reports errors by longjmp; the message is kept here for the exception.
struct PngWriteState {
  std::vector<uint8_t>* out = nullptr;
  char message[256] = {0};
};

void png_write_to_vector(png_structp png, png_bytep data, png_size_t size) {
  auto* state = static_cast<PngWriteState*>(png_get_io_ptr(png));
  state->out->insert(state->out->end(), data, data + size);
}

void png_flush_noop(png_structp) {}

void png_on_error(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngWriteState*>(png_get_error_ptr(png));
  std::strncpy(state->message, message ? message : "unknown", sizeof(state->message) - 1);
  png_longjmp(png, 1);
}

void png_on_warning(png_structp, png_const_charp) {}

}  // namespace

std::vector<uint8_t> encode_jpeg(const CameraImage& image, int quality) {
  check_size(image.width_px, image.height_px, "image");
  const size_t n = static_cast<size_t>(image.width_px) * image.height_px;
  if (image.rgb.size() != 3 * n) {
    throw ConfigError(
        "", "image.rgb",
        "3 * width * height bytes (" + std::to_string(3 * n) + "), got " + std::to_string(image.rgb.size()));
  }
  if (quality < 1 || quality > 100) {
    throw ConfigError("", "quality", "a JPEG quality in 1..100, got " + std::to_string(quality));
  }
  tjhandle handle = tjInitCompress();
  if (!handle) throw InternalError("", "tjInitCompress", tjGetErrorStr());
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  // Defaults of libjpeg(-turbo) give what nuScenes has: a JFIF 1.01 APP0 with density 1:1,
  // baseline Huffman coding, libjpeg's quality-scaled tables; TJSAMP_420 = 2x2 luma.
  const int rc = tjCompress2(handle, image.rgb.data(), image.width_px, 0, image.height_px, TJPF_RGB, &buffer, &size,
                             TJSAMP_420, quality, 0);
  if (rc != 0) {
    const std::string message = tjGetErrorStr2(handle);
    tjFree(buffer);
    tjDestroy(handle);
    throw InternalError("", "tjCompress2", message);
  }
  std::vector<uint8_t> out(buffer, buffer + size);
  tjFree(buffer);
  tjDestroy(handle);
  return out;
}

std::vector<uint8_t> encode_png_gray8(const uint8_t* data, int width_px, int height_px) {
  check_size(width_px, height_px, "png");
  if (data == nullptr) throw ConfigError("", "png", "pixel data (got null)");
  std::vector<uint8_t> out;
  PngWriteState state;
  state.out = &out;
  std::vector<png_const_bytep> rows(static_cast<size_t>(height_px));
  for (int y = 0; y < height_px; ++y) rows[y] = data + static_cast<size_t>(y) * width_px;

  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, png_on_error, png_on_warning);
  if (!png) throw InternalError("", "png_create_write_struct", "out of memory");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw InternalError("", "png_create_info_struct", "out of memory");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw InternalError("", "libpng", state.message);
  }
  png_set_write_fn(png, &state, png_write_to_vector, png_flush_noop);
  // Fixed settings so the bytes depend only on the pixels (no tIME/text chunks are written).
  png_set_compression_level(png, 6);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_ALL_FILTERS);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width_px), static_cast<png_uint_32>(height_px), 8,
               PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, const_cast<png_bytepp>(rows.data()));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

std::vector<uint8_t> encode_png_gray8_from(const CameraImage& image) {
  check_size(image.width_px, image.height_px, "image");
  const size_t n = static_cast<size_t>(image.width_px) * image.height_px;
  if (image.classes.size() != n) {
    throw ConfigError("", "image.classes",
                      "width * height bytes (" + std::to_string(n) + "), got " + std::to_string(image.classes.size()));
  }
  return encode_png_gray8(image.classes.data(), image.width_px, image.height_px);
}

}  // namespace nsg::synth
