#include "gzip.h"

#include <fstream>
#include <iterator>

#include <zlib.h>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg::model {
namespace {
constexpr int kGzipWindowBits = 15 + 16;  // zlib: +16 = gzip wrapper with a zero header
std::string mib(uint64_t bytes) {
  return bytes % (1 << 20) == 0 ? strprintf("%llu MiB", static_cast<unsigned long long>(bytes >> 20))
                                : strprintf("%llu bytes", static_cast<unsigned long long>(bytes));
}
}  // namespace

std::string gzip_compress(const std::string& data) {
  z_stream z{};
  if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, kGzipWindowBits, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw IoError("", "gzip", "zlib to initialise");
  }
  std::string out(deflateBound(&z, static_cast<uLong>(data.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw IoError("", "gzip", "the data to compress in one pass");
  return out;
}

std::string read_maybe_gzip(const std::filesystem::path& path, uint64_t max_text_bytes) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  NSG_CHECK(in.good(), IoError, file, "file", "a readable file");
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  NSG_CHECK(!ec && size <= max_text_bytes, ParseError, file, "file",
            strprintf("a model file of at most %s", mib(max_text_bytes).c_str()));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 2 || static_cast<unsigned char>(bytes[0]) != 0x1f ||
      static_cast<unsigned char>(bytes[1]) != 0x8b) {
    return bytes;
  }
  z_stream z{};
  NSG_CHECK(inflateInit2(&z, kGzipWindowBits) == Z_OK, IoError, file, "gzip", "zlib to initialise");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  std::string out;
  char buf[1 << 16];
  int rc = Z_OK;
  while (rc == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(buf);
    z.avail_out = sizeof buf;
    rc = inflate(&z, Z_NO_FLUSH);
    out.append(buf, sizeof buf - z.avail_out);
    if (out.size() > max_text_bytes) {
      inflateEnd(&z);
      throw ParseError(file, "gzip",
                       strprintf("a model of at most %s inflated (a gzip bomb?)", mib(max_text_bytes).c_str()));
    }
    if (rc == Z_OK && z.avail_in == 0 && z.avail_out != 0) break;  // truncated stream
  }
  inflateEnd(&z);
  NSG_CHECK(rc == Z_STREAM_END, ParseError, file, "gzip", "a complete gzip stream");
  return out;
}

}  // namespace nsg::model
