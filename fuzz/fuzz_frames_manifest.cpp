// Frames manifests (metrics::read_frames_manifest, the one reader of an export's
// manifest.json): any bytes either refused by name (ParseError, IoError) or read into a
// manifest whose every listed path stays inside the export, listed once, with a size ≥ 0 and
// a sha256 of 64 hex digits; its records are then read through read_listed_record from a
// folder that holds none of them (DataError / IoError, never a read outside the folder).
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>

#include "fuzz_support.h"
#include "nsg/core/files.h"
#include "nsg/metrics/frames_documents.h"

namespace {

namespace fs = std::filesystem;

// One folder per process, its manifest.json rewritten for each input.
const fs::path& export_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("nsg-fuzz-frames-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(export_dir() / "manifest.json", std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  nsg::fuzz::expect_only_input_errors([&] {
    nsg::metrics::FramesDocumentLimits limits;
    limits.max_manifest_files = 1000;
    const nsg::metrics::FramesManifest m = nsg::metrics::read_frames_manifest(export_dir(), limits);
    std::set<std::string> seen;
    for (const auto& f : m.files) {
      require(nsg::stays_inside(f.path) && seen.insert(f.path).second && f.bytes >= 0 && f.sha256.size() == 64);
    }
    require(m.window.x_min_m < m.window.x_max_m && m.window.y_min_m < m.window.y_max_m);
    for (const char* split : {"train", "val", "test"})
      for (const nsg::metrics::FramesListedFile* f : m.records(split)) {
        try {
          nsg::metrics::read_listed_record(m, *f, /*verify=*/true, limits);
          std::abort();  // the folder holds no record: nothing can have been read
        } catch (const nsg::DataError&) {
        } catch (const nsg::IoError&) {
        }
      }
  });
  return 0;
}
