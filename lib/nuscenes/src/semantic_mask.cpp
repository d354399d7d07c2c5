#include "nsg/nuscenes/semantic_mask.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>

#include "nsg/core/error.h"

namespace nsg::nuscenes {

namespace {

constexpr png_uint_32 kMaxMaskSidePx = 4096;

// libpng reports errors by longjmp; the message is kept here and turned into a
// ParseError once we are back in C++ (no exceptions through C frames).
struct PngErrorState {
  char message[256] = {0};
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof state->message, "%s", message);
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

// Reads into `out`; returns "" on success or the reason for failure. All C++ objects that
// need destructors live outside the setjmp frame.
std::string read_gray8(std::FILE* f, GrayImage& out, std::vector<png_bytep>& rows) {
  PngErrorState state;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, on_png_error, on_png_warning);
  if (png == nullptr) return "cannot create a PNG reader";
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return "cannot create a PNG reader";
  }
  const char* problem = nullptr;
  bool problem_size = false;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return state.message[0] ? state.message : "a valid PNG";
  }
  png_init_io(png, f);
#if defined(PNG_IGNORE_ADLER32)
  // zlib's Adler-32 of the inflated pixels is not computed: every chunk's CRC-32 already
  // checks the stored bytes, and inflating them is deterministic (≈ 10 % of a mask's decode).
  png_set_option(png, PNG_IGNORE_ADLER32, PNG_OPTION_ON);
#endif
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  const int bit_depth = png_get_bit_depth(png, info), color_type = png_get_color_type(png, info);
  if (bit_depth != 8 || color_type != PNG_COLOR_TYPE_GRAY) {
    problem = "an 8-bit single-channel grayscale PNG";
  } else if (width == 0 || height == 0 || width > kMaxMaskSidePx || height > kMaxMaskSidePx) {
    // Checked on the header, before the pixel buffer: masks are camera-sized (1600 x 900).
    problem = "a mask of at most 4096 x 4096 pixels";
    problem_size = true;
  } else {
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    out.width = static_cast<int>(width);
    out.height = static_cast<int>(height);
    out.pixels.resize(static_cast<size_t>(width) * height);  // may throw bad_alloc: before setjmp use
    rows.resize(height);
    for (png_uint_32 y = 0; y < height; ++y) rows[y] = out.pixels.data() + static_cast<size_t>(y) * width;
    png_read_image(png, rows.data());
    png_read_end(png, nullptr);
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (problem == nullptr) return "";
  std::string reason = problem;
  reason += problem_size
                ? " (got " + std::to_string(width) + " x " + std::to_string(height) + ")"
                : " (got bit depth " + std::to_string(bit_depth) + ", color type " + std::to_string(color_type) + ")";
  return reason;
}

}  // namespace

GrayImage read_semantic_mask(const std::filesystem::path& file) {
  GrayImage out;
  read_semantic_mask(file, out);
  return out;
}

void read_semantic_mask(const std::filesystem::path& file, GrayImage& out) {
  std::FILE* f = std::fopen(file.c_str(), "rb");
  if (f == nullptr) throw IoError(file.string(), "", std::string("cannot open PNG: ") + std::strerror(errno));
  unsigned char signature[8] = {0};
  const bool is_png = std::fread(signature, 1, 8, f) == 8 && png_sig_cmp(signature, 0, 8) == 0;
  if (!is_png) {
    std::fclose(f);
    throw ParseError(file.string(), "", "a PNG file (bad signature)");
  }
  std::rewind(f);
  std::vector<png_bytep> rows;
  const std::string problem = read_gray8(f, out, rows);
  std::fclose(f);
  if (!problem.empty()) throw ParseError(file.string(), "", "expected " + problem);
}

}  // namespace nsg::nuscenes
