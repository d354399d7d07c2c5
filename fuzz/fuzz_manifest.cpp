// A dataset's manifest.json as every command that reads a dataset reads it (io::Dataset::open
// → io::read_manifest): the size bound, the strict parse (nesting, repeated keys), and every
// field and limit of the typed model. What it accepts must keep its shard and map paths
// inside the dataset and its tile side within kMaxTileSizePx, and the one writer must give a
// document the reader reads back to the same bytes.
#include <cstdlib>
#include <string>

#include "fuzz_support.h"
#include "nsg/core/files.h"
#include "nsg/io/manifest.h"
#include "nsg/io/tile_meta.h"

namespace {

void check_model(const nsg::io::Manifest& m) {
  for (const nsg::io::ShardEntry& s : m.shards)
    if (!nsg::stays_inside(s.path()) || s.tiles < 0 || s.bytes < 0) std::abort();
  if (m.ladder)
    for (const nsg::io::ShardEntry& s : m.ladder->shards)
      if (!nsg::stays_inside(s.path()) || s.rung < 1 || s.rung > nsg::io::kMaxRung) std::abort();
  for (const nsg::io::FileRecord& f : m.maps)
    if (!nsg::stays_inside(f.file)) std::abort();
  if (m.tile_format.size_px < 1 || m.tile_format.size_px > nsg::io::kMaxTileSizePx) std::abort();
  if (!(m.tile_format.resolution_m > 0)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nsg::fuzz::expect_only_input_errors([&] {
    const nsg::io::Manifest m = nsg::io::read_manifest(nsg::fuzz::input_file(data, size));
    check_model(m);
    // What the reader accepts, the writer writes and the reader takes back unchanged.
    const std::string text = nsg::io::manifest_text(m);
    try {
      if (nsg::io::manifest_text(nsg::io::manifest_from_text(text, "written")) != text) std::abort();
    } catch (const nsg::Error&) {
      std::abort();  // the writer wrote a manifest its own reader refuses
    }
  });
  return 0;
}
