#include "nsg/nuscenes/camera.h"

#include <turbojpeg.h>

#include "nsg/core/error.h"
#include "nsg/core/files.h"

namespace nsg::nuscenes {
namespace {
// nuScenes cameras are 1600 x 900; the header is checked before any pixel buffer is
// allocated, so a small file claiming a huge image costs nothing.
constexpr int kMaxJpegSidePx = 4096;
}  // namespace

struct JpegDecoder::Impl {
  tjhandle handle = nullptr;
};

int scaled_dimension(int full, JpegScale scale) {
  const tjscalingfactor factor{1, static_cast<int>(scale)};
  return TJSCALED(full, factor);
}

JpegDecoder::JpegDecoder() : impl_(std::make_unique<Impl>()) {
  impl_->handle = tjInitDecompress();
  if (impl_->handle == nullptr)
    throw InternalError("", "", std::string("tjInitDecompress failed: ") + tjGetErrorStr2(nullptr));
}

JpegDecoder::~JpegDecoder() {
  if (impl_ && impl_->handle != nullptr) tjDestroy(impl_->handle);
}

std::pair<int, int> JpegDecoder::read_size(const std::uint8_t* data, size_t size, const std::string& name) {
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (size == 0 || tjDecompressHeader3(impl_->handle, data, static_cast<unsigned long>(size), &width, &height,
                                       &subsampling, &colorspace) != 0) {
    throw ParseError(name, "", std::string("a JPEG image (header: ") + tjGetErrorStr2(impl_->handle) + ")");
  }
  NSG_CHECK(width > 0 && height > 0 && width <= kMaxJpegSidePx && height <= kMaxJpegSidePx, ParseError, name,
            "JPEG header",
            "a camera image of at most " + std::to_string(kMaxJpegSidePx) + " x " + std::to_string(kMaxJpegSidePx) +
                " pixels, got " + std::to_string(width) + " x " + std::to_string(height));
  return {width, height};
}

void JpegDecoder::decode(const std::uint8_t* data, size_t size, JpegScale scale, RgbImage& out,
                         const std::string& name) {
  const auto [full_w, full_h] = read_size(data, size, name);
  out.width = scaled_dimension(full_w, scale);
  out.height = scaled_dimension(full_h, scale);
  out.pixels.resize(static_cast<size_t>(out.width) * out.height * 3);
  // Warnings (e.g. premature end of data) count as errors: a partial image is not data.
  if (tjDecompress2(impl_->handle, data, static_cast<unsigned long>(size), out.pixels.data(), out.width, 0, out.height,
                    TJPF_RGB, TJFLAG_STOPONWARNING) != 0) {
    throw ParseError(name, "", std::string("a valid JPEG image (decode: ") + tjGetErrorStr2(impl_->handle) + ")");
  }
}

void JpegDecoder::decode_file(const std::filesystem::path& file, JpegScale scale, RgbImage& out) {
  const std::string bytes = read_file(file);
  decode(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), scale, out, file.string());
}

RgbImage JpegDecoder::decode_file(const std::filesystem::path& file, JpegScale scale) {
  RgbImage out;
  decode_file(file, scale, out);
  return out;
}

}  // namespace nsg::nuscenes
