// WebDataset tar shards through libarchive: ustar headers (pax only for long names), fixed
// owner/time/mode so identical members give identical bytes.
#include <archive.h>
#include <archive_entry.h>

#include <cstdio>
#include <exception>
#include <fstream>
#include <set>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "nsg/io/tar.h"
#include "nsg/io/tar_index.h"

namespace fs = std::filesystem;

namespace nsg::io {
namespace {

constexpr int kTarBlockBytes = 512;
constexpr size_t kReadBlockBytes = 1 << 16;

struct ArchiveWriteFree {
  void operator()(archive* a) const { archive_write_free(a); }
};
struct ArchiveReadFree {
  void operator()(archive* a) const { archive_read_free(a); }
};
struct EntryFree {
  void operator()(archive_entry* e) const { archive_entry_free(e); }
};

std::string archive_message(archive* a) {
  const char* s = archive_error_string(a);
  return s != nullptr ? s : "unknown libarchive error";
}

void check_member_name(const fs::path& file, const std::string& name) {
  NSG_CHECK(!name.empty() && name.front() != '/' && name.back() != '/', ConfigError, file.string(),
            "member '" + name + "'", "a non-empty relative file name");
  NSG_CHECK(name.find('\0') == std::string::npos, ConfigError, file.string(), "member", "a name without NUL bytes");
  for (const auto& part : fs::path(name)) {
    NSG_CHECK(part != "..", ConfigError, file.string(), "member '" + name + "'", "a name without '..' components");
  }
}

}  // namespace

// ---- writer ---------------------------------------------------------------------------------

struct TarWriter::Impl {
  fs::path final_path;
  AtomicFileWriter file;
  Sha256 sha;
  uint64_t bytes = 0;
  size_t members = 0;
  std::set<std::string> names;
  std::unique_ptr<archive, ArchiveWriteFree> ar;
  std::exception_ptr callback_error;  // exceptions must not cross libarchive's C frames
  bool finished = false;

  explicit Impl(fs::path path) : final_path(path), file(path) {}

  static la_ssize_t write_cb(archive*, void* self, const void* buf, size_t n) {
    auto* impl = static_cast<Impl*>(self);
    try {
      impl->file.write(buf, n);
      impl->sha.update(buf, n);
      impl->bytes += n;
      return static_cast<la_ssize_t>(n);
    } catch (...) {
      impl->callback_error = std::current_exception();
      return -1;
    }
  }

  [[noreturn]] void fail(const std::string& record) {
    if (callback_error) std::rethrow_exception(callback_error);
    throw IoError(final_path.string(), record, "tar write failed: " + archive_message(ar.get()));
  }
};

TarWriter::TarWriter(fs::path final_path) : impl_(std::make_unique<Impl>(std::move(final_path))) {
  impl_->ar.reset(archive_write_new());
  archive* a = impl_->ar.get();
  if (a == nullptr) throw InternalError(impl_->final_path.string(), "", "archive_write_new failed");
  // pax_restricted = plain ustar unless a name needs an extended header.
  if (archive_write_set_format_pax_restricted(a) != ARCHIVE_OK ||
      archive_write_open2(a, impl_.get(), nullptr, &Impl::write_cb, nullptr, nullptr) != ARCHIVE_OK) {
    impl_->fail("");
  }
}

TarWriter::~TarWriter() = default;  // unfinished: AtomicFileWriter removes the temp file

void TarWriter::add(const std::string& member_name, std::span<const uint8_t> bytes) {
  Impl& w = *impl_;
  if (w.finished) throw InternalError(w.final_path.string(), member_name, "add after finish");
  check_member_name(w.final_path, member_name);
  NSG_CHECK(w.names.insert(member_name).second, ConfigError, w.final_path.string(), "member '" + member_name + "'",
            "unique member names (already added)");
  std::unique_ptr<archive_entry, EntryFree> entry(archive_entry_new());
  archive_entry* e = entry.get();
  archive_entry_set_pathname(e, member_name.c_str());
  archive_entry_set_filetype(e, AE_IFREG);
  archive_entry_set_perm(e, 0644);
  archive_entry_set_size(e, static_cast<la_int64_t>(bytes.size()));
  archive_entry_set_mtime(e, 0, 0);
  archive_entry_set_uid(e, 0);
  archive_entry_set_gid(e, 0);
  if (archive_write_header(w.ar.get(), e) != ARCHIVE_OK) w.fail(member_name);
  size_t done = 0;
  while (done < bytes.size()) {
    const la_ssize_t n = archive_write_data(w.ar.get(), bytes.data() + done, bytes.size() - done);
    if (n <= 0) w.fail(member_name);
    done += static_cast<size_t>(n);
  }
  if (archive_write_finish_entry(w.ar.get()) != ARCHIVE_OK) w.fail(member_name);
  ++w.members;
}

TarWriter::Result TarWriter::finish() {
  Impl& w = *impl_;
  if (w.finished) throw InternalError(w.final_path.string(), "", "finish twice");
  // Writes the end-of-archive blocks and pads the last record.
  if (archive_write_close(w.ar.get()) != ARCHIVE_OK) w.fail("end of archive");
  w.file.commit();
  w.finished = true;
  return Result{w.sha.hex_digest(), w.bytes, w.members};
}

// ---- reader ---------------------------------------------------------------------------------

struct TarReader::Impl {
  fs::path path;
  std::unique_ptr<archive, ArchiveReadFree> ar;
  std::string last_member;
  std::set<std::string> names;  // members read so far: each name once
  bool at_end = false;

  // libarchive accepts a tar cut off exactly between members as complete (some writers
  // omit the end marker); we require the two zero blocks so truncation cannot pass.
  void require_end_marker() {
    const la_int64_t end_of_members = archive_read_header_position(ar.get());
    std::ifstream in(path, std::ios::binary);
    char block[2 * kTarBlockBytes] = {};
    in.seekg(end_of_members);
    in.read(block, sizeof block);
    bool zeros = in.gcount() == static_cast<std::streamsize>(sizeof block);
    for (size_t i = 0; zeros && i < sizeof block; ++i) zeros = block[i] == 0;
    NSG_CHECK(zeros, ParseError, path.string(),
              last_member.empty() ? "end of archive" : "after member '" + last_member + "'",
              "the end-of-archive marker (two zero blocks); the archive is truncated");
  }

  [[noreturn]] void fail(const std::string& record) {
    throw ParseError(path.string(), record, "corrupt or truncated tar: " + archive_message(ar.get()));
  }
};

TarReader::TarReader(const fs::path& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  std::error_code ec;
  NSG_CHECK(fs::is_regular_file(path, ec) && std::ifstream(path, std::ios::binary).good(), IoError, path.string(), "",
            "a readable tar file");
  impl_->ar.reset(archive_read_new());
  archive* a = impl_->ar.get();
  if (a == nullptr) throw InternalError(path.string(), "", "archive_read_new failed");
  archive_read_support_format_tar(a);
  if (archive_read_open_filename(a, path.c_str(), kReadBlockBytes) != ARCHIVE_OK) {
    // The file is readable (checked above), so libarchive refused its content.
    throw ParseError(path.string(), "first header", "a tar archive: " + archive_message(a));
  }
}

TarReader::~TarReader() = default;

bool TarReader::next(TarMember& out) {
  Impl& r = *impl_;
  if (r.at_end) return false;
  archive* a = r.ar.get();
  for (;;) {
    archive_entry* e = nullptr;
    const int status = archive_read_next_header(a, &e);
    if (status == ARCHIVE_EOF) {
      r.at_end = true;
      r.require_end_marker();
      return false;
    }
    if (status != ARCHIVE_OK) {
      r.fail(r.last_member.empty() ? "first header" : "header after member '" + r.last_member + "'");
    }
    const char* pathname = archive_entry_pathname(e);
    const std::string name = pathname != nullptr ? pathname : "";
    r.last_member = name;
    // The same members index_tar accepts: regular files with safe, unique names; folders
    // are skipped; links and special files refused.
    const auto type = archive_entry_filetype(e);
    if (type == AE_IFDIR) continue;
    check_tar_member_type(r.path.string(), name, type == AE_IFREG ? '0' : type == AE_IFLNK ? '2' : '3');
    if (archive_entry_hardlink(e) != nullptr) check_tar_member_type(r.path.string(), name, '1');
    check_tar_member_name(r.path.string(), name);
    NSG_CHECK(r.names.insert(name).second, ParseError, r.path.string(), "member '" + name + "'",
              "each member name once");
    const la_int64_t size = archive_entry_size(e);
    std::error_code ec;
    const auto file_size = fs::file_size(r.path, ec);
    NSG_CHECK(size >= 0 && !ec && static_cast<uint64_t>(size) <= file_size, ParseError, r.path.string(),
              "member '" + name + "'", "a size within the archive");
    out.name = name;
    out.bytes.resize(static_cast<size_t>(size));
    size_t done = 0;
    while (done < out.bytes.size()) {
      const la_ssize_t n = archive_read_data(a, out.bytes.data() + done, out.bytes.size() - done);
      if (n < 0) r.fail("member '" + name + "'");
      if (n == 0) {
        throw ParseError(r.path.string(), "member '" + name + "'",
                         std::to_string(size) + " bytes of data, the archive ends after " + std::to_string(done));
      }
      done += static_cast<size_t>(n);
    }
    return true;
  }
}

}  // namespace nsg::io
