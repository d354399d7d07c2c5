// Header-only pass over a tar (POSIX 1003.1 ustar, pax extended headers, GNU long names),
// for random access by offset. libarchive streams members but does not expose data
// offsets, hence this small reader of the fixed header layout.
#include "nsg/io/tar_index.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <optional>
#include <set>

#include "nsg/core/error.h"

namespace fs = std::filesystem;

namespace nsg::io {
namespace {

constexpr uint64_t kBlock = 512;

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

uint64_t padded(uint64_t n) { return (n + kBlock - 1) / kBlock * kBlock; }

// Octal field (NUL/space padded) or GNU base-256 (high bit set) of a header.
std::optional<uint64_t> parse_number(const char* field, size_t width) {
  const auto* u = reinterpret_cast<const unsigned char*>(field);
  if (u[0] & 0x80) {
    uint64_t v = u[0] & 0x7f;
    for (size_t i = 1; i < width; ++i) v = (v << 8) | u[i];
    return v;
  }
  uint64_t v = 0;
  size_t i = 0;
  while (i < width && field[i] == ' ') ++i;
  bool any = false;
  for (; i < width && field[i] >= '0' && field[i] <= '7'; ++i, any = true) v = v * 8 + (field[i] - '0');
  for (; i < width; ++i)
    if (field[i] != ' ' && field[i] != '\0') return std::nullopt;
  return any ? std::optional<uint64_t>(v) : std::optional<uint64_t>(0);
}

std::string field_string(const char* field, size_t width) { return std::string(field, strnlen(field, width)); }

bool checksum_ok(const unsigned char* h) {
  const auto stored = parse_number(reinterpret_cast<const char*>(h) + 148, 8);
  if (!stored) return false;
  uint64_t sum = 0;
  for (size_t i = 0; i < kBlock; ++i) sum += (i >= 148 && i < 156) ? ' ' : h[i];
  return sum == *stored;
}

// pax records "<len> <key>=<value>\n": the "path" and "size" overrides.
void apply_pax(const std::string& text, std::string* path, std::optional<uint64_t>* size, const std::string& file,
               const std::string& where) {
  size_t at = 0;
  while (at < text.size()) {
    const size_t space = text.find(' ', at);
    NSG_CHECK(space != std::string::npos, ParseError, file, where, "pax records '<length> <key>=<value>\\n'");
    const uint64_t len = std::strtoull(text.c_str() + at, nullptr, 10);
    NSG_CHECK(len > space - at && at + len <= text.size(), ParseError, file, where,
              "a pax record length within the header");
    const std::string record = text.substr(space + 1, at + len - space - 2);  // without the '\n'
    const size_t eq = record.find('=');
    if (eq != std::string::npos) {
      const std::string key = record.substr(0, eq), value = record.substr(eq + 1);
      if (key == "path") *path = value;
      if (key == "size") {
        // Decimal digits only, without overflow: strtoull would saturate a hostile value.
        uint64_t v = 0;
        bool ok = !value.empty();
        for (char ch : value) {
          const auto digit = static_cast<uint64_t>(ch - '0');
          ok = ok && ch >= '0' && ch <= '9' && v <= (UINT64_MAX - digit) / 10;
          if (ok) v = v * 10 + digit;
        }
        NSG_CHECK(ok, ParseError, file, where, "a pax size in decimal digits below 2^64, got '" + value + "'");
        *size = v;
      }
    }
    at += len;
  }
}

}  // namespace

void check_tar_member_name(const std::string& file, const std::string& name) {
  NSG_CHECK(!name.empty() && name.front() != '/', ParseError, file, "member '" + name + "'",
            "a relative member name (not absolute)");
  NSG_CHECK(name.find('\0') == std::string::npos, ParseError, file, "member", "a name without NUL bytes");
  for (const auto& part : fs::path(name))
    NSG_CHECK(part != "..", ParseError, file, "member '" + name + "'", "a name without '..' components");
}

void check_tar_member_type(const std::string& file, const std::string& name, char type) {
  const bool regular = type == '0' || type == '\0' || type == '7';
  NSG_CHECK(regular || type == '5', ParseError, file, "member '" + name + "'",
            std::string("regular files (and folders) only, not a ") +
                (type == '1'   ? "hard link"
                 : type == '2' ? "symbolic link"
                               : "special file") +
                " (type '" + std::string(1, type) + "')");
}

void read_at(int fd, uint64_t offset, void* out, size_t size, const std::string& file_label,
             const std::string& record) {
  auto* p = static_cast<char*>(out);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pread(fd, p + done, size - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    NSG_CHECK(n >= 0, IoError, file_label, record, std::string("a readable file: ") + std::strerror(errno));
    NSG_CHECK(n > 0, IoError, file_label, record,
              std::to_string(size) + " bytes at offset " + std::to_string(offset) + ", the file ends before");
    done += static_cast<size_t>(n);
  }
}

std::vector<TarIndexEntry> index_tar(const fs::path& path) {
  const std::string file = path.string();
  Fd f;
  f.fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  NSG_CHECK(f.fd >= 0, IoError, file, "", std::string("a readable tar file: ") + std::strerror(errno));
  std::error_code ec;
  const uint64_t file_size = fs::file_size(path, ec);
  NSG_CHECK(!ec, IoError, file, "", "a readable tar file: " + ec.message());

  std::vector<TarIndexEntry> out;
  std::set<std::string> names;
  std::string long_name;             // from a pax 'x' or GNU 'L' header, for the next member
  std::optional<uint64_t> pax_size;  // from a pax 'x' header
  uint64_t at = 0;
  unsigned char h[kBlock];
  for (;;) {
    const std::string where =
        out.empty() ? "header at byte " + std::to_string(at) : "header after member '" + out.back().name + "'";
    NSG_CHECK(at + 2 * kBlock <= file_size, ParseError, file, where,
              "the end-of-archive marker (two zero blocks); the archive is truncated");
    read_at(f.fd, at, h, kBlock, file, where);
    if (std::all_of(h, h + kBlock, [](unsigned char c) { return c == 0; })) break;  // end marker
    NSG_CHECK(checksum_ok(h), ParseError, file, where, "a tar header with a valid checksum");
    const char* c = reinterpret_cast<const char*>(h);
    const std::optional<uint64_t> octal_size = parse_number(c + 124, 12);
    NSG_CHECK(octal_size.has_value(), ParseError, file, where, "an octal member size");
    const char type = c[156];
    uint64_t size = *octal_size;
    std::string name = field_string(c, 100);
    if (std::memcmp(c + 257, "ustar", 5) == 0 && c[345] != '\0') name = field_string(c + 345, 155) + "/" + name;
    const uint64_t data = at + kBlock;
    if (type == 'g') {  // a global pax header: nothing we use
      NSG_CHECK(size <= file_size - data, ParseError, file, where, "a global header within the file");
      at = data + padded(size);
      continue;
    }
    if (type == 'x' || type == 'L') {
      NSG_CHECK(size < (1u << 20) && size <= file_size - data, ParseError, file, where,
                "an extended header of < 1 MiB within the file");
      std::string text(size, '\0');
      read_at(f.fd, data, text.data(), size, file, where);
      if (type == 'x') apply_pax(text, &long_name, &pax_size, file, where);
      else long_name = field_string(text.data(), text.size());
      at = data + padded(size);
      continue;
    }
    if (pax_size) size = *pax_size;  // pax size overrides the octal field
    if (!long_name.empty()) name = long_name;
    // `data <= file_size` holds (checked above): compare without forming data + size, which
    // a hostile size would wrap around to an earlier offset.
    NSG_CHECK(size <= file_size - data, ParseError, file, "member '" + name + "'",
              std::to_string(size) + " bytes of data within the archive");
    check_tar_member_type(file, name, type);
    if (type != '5') {  // folders: not samples
      check_tar_member_name(file, name);
      NSG_CHECK(names.insert(name).second, ParseError, file, "member '" + name + "'", "each member name once");
      out.push_back({name, data, size});
    }
    long_name.clear();
    pax_size.reset();
    at = data + padded(size);
  }
  return out;
}

}  // namespace nsg::io
