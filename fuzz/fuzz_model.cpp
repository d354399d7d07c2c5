// A model file as `nsgraph predict` loads it (model::LaneModel::load), plain YAML and
// gzip: the inflated-size bound, the format checks and the forest's tree structure,
// checked before OpenCV builds the trees. A cut, bombed or malformed file may only raise
// input errors.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "fuzz_support.h"
#include "nsg/model/model.h"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A named file: the loader picks gzip or plain by the bytes, OpenCV by the extension.
  static const fs::path path = fs::temp_directory_path() / ("nsg-fuzz-model-" + std::to_string(::getpid()) + ".yml");
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  // Model text up to 4 MiB: a 64 KiB gzip inflating to 60 MiB of YAML is a valid bounded
  // input (2 s in a Release build) but overran the 10 s per-input budget under the
  // sanitizers; the 256 MiB bound itself is HostileModel.GzipBombIsStoppedAtTheLimit's.
  nsg::fuzz::expect_only_input_errors([&] { (void)nsg::model::LaneModel::load(path, uint64_t{4} << 20); });
  return 0;
}
