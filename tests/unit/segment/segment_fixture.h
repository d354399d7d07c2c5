#pragma once
// Shared by the segment tests: the tiny test model (tests/data/segment, made by
// make_tiny_models.py) and `nsgraph segment` runs over the pipeline tests' cached releases.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "test_support.h"

namespace nsg::test {

inline std::filesystem::path segment_data() { return source_dir() / "tests" / "data" / "segment"; }
inline std::filesystem::path tiny_model() { return segment_data() / "synth-colours.onnx"; }
inline std::filesystem::path tiny_labels() { return segment_data() / "synth-colours.json"; }

inline std::vector<std::string> segment_args(const std::filesystem::path& release, const std::filesystem::path& out,
                                             const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args = {
      "segment",   "--quiet",   "--dataroot",          release.string(), "--version",
      "v1.0-mini", "--model",   tiny_model().string(), "--labels",       tiny_labels().string(),
      "--out",     out.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// The masks `segment` makes for a cached release at 2 threads, made once per build.
inline std::filesystem::path segment_masks(const std::string& name, const std::filesystem::path& release) {
  const std::string key =
      nsgraph_build_key() + "-" + sha256_hex(read_file(tiny_model()) + read_file(tiny_labels())).substr(0, 16);
  return cached_folder("segment_" + name, key, [&](const std::filesystem::path& dir) {
    const CommandResult r = run_nsgraph(segment_args(release, dir, {"--threads", "2"}));
    if (r.exit_code != 0) throw std::runtime_error("segment " + name + " failed: " + r.err);
  });
}

}  // namespace nsg::test
