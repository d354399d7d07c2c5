// A share's done-record as `nsgraph merge` reads it (parts/share-000000-of-000001.json in a
// fresh dataset folder): the strict parser, the record's field checks and the item paths
// kept inside the folder. A record naming files outside the folder, mistyped fields or a
// nesting beyond the limit may only raise input errors, and nothing outside the folder
// is touched.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "fuzz_support.h"
#include "nsg/pipeline/generate.h"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const fs::path root = fs::temp_directory_path() / ("nsg-fuzz-merge-" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "parts");
  {
    std::ofstream out(root / "parts" / "share-000000-of-000001.json", std::ios::binary);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  nsg::fuzz::expect_only_input_errors([&] { nsg::pipeline::merge(root); });
  return 0;
}
