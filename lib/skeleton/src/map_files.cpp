// Reading a tile's map from a stranger's file: the kind from its first bytes, the size
// from its header (bounded before anything is allocated), then the pixels.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <regex>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <zlib.h>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/io/raster.h"
#include "nsg/skeleton/graphify.h"

namespace nsg::skeleton {
namespace {

const std::string kSizeExpectation =
    "width and height each 1 … " + std::to_string(kMaxMapSidePx) + " px (graphify's tile limit)";

bool starts_with_bytes(const std::string& bytes, const char* magic, size_t n) {
  return bytes.size() >= n && std::memcmp(bytes.data(), magic, n) == 0;
}

void check_size(int64_t width_px, int64_t height_px, const std::string& file, const std::string& record) {
  const bool ok = width_px >= 1 && height_px >= 1 && width_px <= kMaxMapSidePx && height_px <= kMaxMapSidePx;
  NSG_CHECK(ok, DataError, file, record,
            kSizeExpectation + ", got " + std::to_string(width_px) + " x " + std::to_string(height_px));
}

uint32_t big_endian_u32(const std::string& b, size_t at) {
  return (static_cast<uint32_t>(static_cast<uint8_t>(b[at])) << 24) |
         (static_cast<uint32_t>(static_cast<uint8_t>(b[at + 1])) << 16) |
         (static_cast<uint32_t>(static_cast<uint8_t>(b[at + 2])) << 8) | static_cast<uint8_t>(b[at + 3]);
}

// The bytes a PNG's image data inflates to: per row a filter byte and the row's samples,
// over the seven Adam7 passes when interlaced (PNG specification, sections 7.2 and 8.2).
uint64_t png_inflated_bytes(uint32_t width, uint32_t height, int bytes_per_px, bool interlaced) {
  const auto rows_bytes = [&](uint64_t w, uint64_t h) { return w == 0 || h == 0 ? 0 : h * (1 + w * bytes_per_px); };
  if (!interlaced) return rows_bytes(width, height);
  constexpr int kStartX[7] = {0, 4, 0, 2, 0, 1, 0}, kStartY[7] = {0, 0, 4, 0, 2, 0, 1};
  constexpr int kStepX[7] = {8, 8, 4, 4, 2, 2, 1}, kStepY[7] = {8, 8, 8, 4, 4, 2, 2};
  uint64_t total = 0;
  for (int p = 0; p < 7; ++p) {
    const uint64_t w = width > static_cast<uint32_t>(kStartX[p]) ? (width - kStartX[p] + kStepX[p] - 1) / kStepX[p] : 0;
    const uint64_t h =
        height > static_cast<uint32_t>(kStartY[p]) ? (height - kStartY[p] + kStepY[p] - 1) / kStepY[p] : 0;
    total += rows_bytes(w, h);
  }
  return total;
}

// The image data of a PNG (its IDAT chunks, in order) inflates to exactly `expected`
// bytes: checked here with zlib and a bounded output before any decoder sees the file, so
// a deflate bomb (IDAT that inflates far beyond the image, which the decoder would still
// inflate to its end) costs at most the image's own size in time and nothing in memory.
void check_png_data(const std::string& bytes, uint64_t expected, const std::string& file) {
  z_stream z{};
  NSG_CHECK(inflateInit(&z) == Z_OK, InternalError, file, "PNG data", "a zlib stream");
  std::vector<unsigned char> sink(1 << 16);
  uint64_t produced = 0;
  bool ended = false;
  const auto fail = [&](const std::string& what) {
    inflateEnd(&z);
    throw ParseError(file, "PNG data", what);
  };
  for (size_t at = 8; at + 12 <= bytes.size() && !ended;) {
    const uint32_t length = big_endian_u32(bytes, at);
    if (length > bytes.size() - at - 12) fail("chunks within the file (a chunk's length runs past its end)");
    const std::string type = bytes.substr(at + 4, 4);
    if (type == "IEND") break;
    if (type == "IDAT") {
      z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + at + 8));
      z.avail_in = length;
      while (z.avail_in > 0 && !ended) {
        z.next_out = sink.data();
        z.avail_out = static_cast<uInt>(sink.size());
        const int rc = inflate(&z, Z_NO_FLUSH);
        produced += sink.size() - z.avail_out;
        if (produced > expected)
          fail("image data that inflates to the image's " + std::to_string(expected) +
               " bytes (it inflates to more: a deflate bomb or a corrupt file)");
        if (rc == Z_STREAM_END) ended = true;
        else if (rc == Z_BUF_ERROR) break;  // no progress: the stream needs the next chunk
        else if (rc != Z_OK) fail("a valid zlib stream in its IDAT chunks");
      }
    }
    at += 12 + static_cast<size_t>(length);
  }
  inflateEnd(&z);
  if (produced != expected)
    throw ParseError(file, "PNG data",
                     "image data that inflates to the image's " + std::to_string(expected) + " bytes, got " +
                         std::to_string(produced) + " (the file is truncated or corrupt)");
}

// PNG: the IHDR chunk (always first) gives size, bit depth and colour type; the image data
// is checked to inflate to that size (check_png_data); only then decode.
cv::Mat read_png(const std::string& bytes, const std::string& file) {
  NSG_CHECK(bytes.size() >= 33 && bytes.compare(12, 4, "IHDR") == 0, ParseError, file, "PNG header",
            "an IHDR chunk after the signature (the file is truncated or not a PNG)");
  check_size(big_endian_u32(bytes, 16), big_endian_u32(bytes, 20), file, "PNG header");
  const int depth = static_cast<uint8_t>(bytes[24]), colour = static_cast<uint8_t>(bytes[25]);
  NSG_CHECK(colour == 0 && (depth == 8 || depth == 16), DataError, file, "PNG header",
            "8- or 16-bit grayscale (colour type 0), got colour type " + std::to_string(colour) + " at " +
                std::to_string(depth) + " bit");
  const bool interlaced = static_cast<uint8_t>(bytes[28]) == 1;
  check_png_data(bytes, png_inflated_bytes(big_endian_u32(bytes, 16), big_endian_u32(bytes, 20), depth / 8, interlaced),
                 file);
  const cv::Mat raw(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
  cv::Mat image;
  try {
    image = cv::imdecode(raw, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    image.release();
  }
  const int want_type = depth == 8 ? CV_8UC1 : CV_16UC1;
  NSG_CHECK(!image.empty() && image.type() == want_type && image.cols == static_cast<int>(big_endian_u32(bytes, 16)) &&
                image.rows == static_cast<int>(big_endian_u32(bytes, 20)),
            ParseError, file, "PNG data", "a complete PNG image (the file is truncated or corrupt)");
  return image;
}

// TIFF: through the dataset's GeoTIFF reader (io::decode_geotiff, which refuses more than
// 4096 x 4096 from the header); one band, uint8 or float32.
cv::Mat read_tiff(const std::string& bytes, const std::string& file) {
  const std::span<const uint8_t> span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  const io::RasterHeader header = io::read_geotiff_header(span, file);
  check_size(header.width, header.height, file, "TIFF header");
  NSG_CHECK(header.bands == 1, DataError, file, "TIFF header", "one band, got " + std::to_string(header.bands));
  const io::Raster r = io::decode_geotiff(span, file);
  const int type = r.type == io::SampleType::kFloat32 ? CV_32F : CV_8U;
  return cv::Mat(r.height, r.width, type, const_cast<uint8_t*>(r.data.data())).clone();
}

// The value of `key` in a .npy header (a Python dict literal): the text after "'key':".
std::string npy_field(const std::string& header, const std::string& key, const std::string& file) {
  const size_t at = header.find("'" + key + "'");
  NSG_CHECK(at != std::string::npos, ParseError, file, ".npy header", "a '" + key + "' entry");
  const size_t colon = header.find(':', at);
  NSG_CHECK(colon != std::string::npos, ParseError, file, ".npy header", "'" + key + "': value");
  return header.substr(colon + 1);
}

// The array's shape: the integers of the "(a, b)" tuple; DataError unless exactly two.
std::vector<int64_t> npy_shape(const std::string& header, const std::string& file) {
  const std::string rest = npy_field(header, "shape", file);
  static const std::regex tuple(R"(^\s*\(([0-9,\s]*)\))");
  std::smatch m;
  NSG_CHECK(std::regex_search(rest, m, tuple), ParseError, file, ".npy header", "'shape': a tuple of integers");
  std::vector<int64_t> dims;
  const std::string items = m[1].str();
  static const std::regex number(R"([0-9]{1,12})");
  for (auto it = std::sregex_iterator(items.begin(), items.end(), number); it != std::sregex_iterator(); ++it)
    dims.push_back(std::stoll(it->str()));
  NSG_CHECK(dims.size() == 2, DataError, file, ".npy shape",
            "a 2-D array (rows, columns), got " + std::to_string(dims.size()) + " dimension(s)");
  return dims;
}

// NumPy .npy (format versions 1 to 3): the header's dtype, order and shape, then the data,
// whose length must be exactly rows x columns x item size.
cv::Mat read_npy(const std::string& bytes, const std::string& file) {
  NSG_CHECK(bytes.size() >= 10, ParseError, file, ".npy header", "a complete header (the file is truncated)");
  const int major = static_cast<uint8_t>(bytes[6]);
  NSG_CHECK(major >= 1 && major <= 3, ParseError, file, ".npy header", "format version 1, 2 or 3");
  const size_t len_bytes = major == 1 ? 2 : 4, start = 8 + len_bytes;
  size_t header_len = 0;
  for (size_t k = 0; k < len_bytes && 8 + k < bytes.size(); ++k)
    header_len |= static_cast<size_t>(static_cast<uint8_t>(bytes[8 + k])) << (8 * k);
  NSG_CHECK(bytes.size() >= start && header_len <= bytes.size() - start, ParseError, file, ".npy header",
            "a complete header (the file is truncated)");
  const std::string header = bytes.substr(start, header_len);
  const std::string descr = npy_field(header, "descr", file);
  const bool f4 = descr.find("'<f4'") != std::string::npos, u1 = descr.find("'|u1'") != std::string::npos;
  NSG_CHECK(f4 || u1, DataError, file, ".npy dtype",
            "float32 ('<f4') or uint8 ('|u1'), got " + descr.substr(0, descr.find(',')));
  const bool fortran = npy_field(header, "fortran_order", file).find("True") < 3;
  const std::vector<int64_t> dims = npy_shape(header, file);
  check_size(dims[1], dims[0], file, ".npy shape");
  const size_t item = f4 ? 4 : 1, data_bytes = static_cast<size_t>(dims[0] * dims[1]) * item;
  NSG_CHECK(bytes.size() - start - header_len == data_bytes, ParseError, file, ".npy data",
            std::to_string(data_bytes) + " bytes of data after the header, got " +
                std::to_string(bytes.size() - start - header_len));
  const int rows = static_cast<int>(fortran ? dims[1] : dims[0]), cols = static_cast<int>(fortran ? dims[0] : dims[1]);
  cv::Mat m(rows, cols, f4 ? CV_32F : CV_8U);
  std::memcpy(m.data, bytes.data() + start + header_len, data_bytes);  // little-endian, as this machine
  return fortran ? cv::Mat(m.t()) : m;
}

}  // namespace

bool is_map_file_name(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".tif" || ext == ".tiff" || ext == ".npy";
}

cv::Mat read_map_file(const std::filesystem::path& path) {
  const std::string file = path.string();
  require_file(path, "map");
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  NSG_CHECK(!ec, IoError, file, "", "a readable file: " + ec.message());
  NSG_CHECK(size <= kMaxMapFileBytes, DataError, file, "",
            "at most " + std::to_string(kMaxMapFileBytes >> 20) + " MiB (graphify's map file limit)");
  const std::string bytes = read_file(path);
  cv::Mat map;
  if (starts_with_bytes(bytes, "\x89PNG\r\n\x1a\n", 8)) map = read_png(bytes, file);
  else if (starts_with_bytes(bytes, "II*\0", 4) || starts_with_bytes(bytes, "MM\0*", 4)) map = read_tiff(bytes, file);
  else if (starts_with_bytes(bytes, "\x93NUMPY", 6)) map = read_npy(bytes, file);
  else throw ParseError(file, "", "a PNG, TIFF or NumPy .npy file (by its first bytes)");
  if (map.depth() == CV_32F)
    NSG_CHECK(cv::checkRange(map), DataError, file, "values", "finite numbers (no NaN or infinity)");
  return map;
}

}  // namespace nsg::skeleton
