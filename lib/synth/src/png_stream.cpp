#include "png_stream.h"

#include <png.h>

#include <csetjmp>
#include <vector>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"

namespace nsg::synth {

namespace {
void png_error_fn(png_structp png, png_const_charp msg) {
  auto* text = static_cast<std::string*>(png_get_error_ptr(png));
  if (text) *text = msg;
  png_longjmp(png, 1);
}
void png_warn_fn(png_structp, png_const_charp) {}
}  // namespace

void write_gray_png_rows(const std::filesystem::path& target, int width, int height,
                         const std::function<void(int, uint8_t*)>& fill_row) {
  if (width <= 0 || height <= 0) throw InternalError(target.string(), "", "PNG size must be positive");
  AtomicFileWriter writer(target);
  std::string error;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, png_error_fn, png_warn_fn);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw IoError(target.string(), "", "cannot initialise libpng");
  }
  std::vector<uint8_t> row(static_cast<size_t>(width));
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw IoError(target.string(), "", "PNG encoding failed: " + error);
  }
  png_init_io(png, writer.file());
  png_set_compression_level(png, 6);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int r = 0; r < height; ++r) {
    fill_row(r, row.data());
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  writer.commit();
}

}  // namespace nsg::synth
