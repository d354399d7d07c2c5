#pragma once
// Helpers shared by the test binaries: source paths, scratch folders, running the CLI.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace nsg::test {

// Repository root (for samples/, schemas/) and the tests' data folder (tests/data: golden
// values, the real key frame, fixtures).
std::filesystem::path source_dir();
std::filesystem::path data_dir();
// Path of the built nsgraph binary.
std::filesystem::path nsgraph_exe();

// A fresh folder under the build tree's scratch area, removed when destroyed
// (kept if NSG_KEEP_TMP is set, for debugging).
class TempDir {
 public:
  explicit TempDir(const std::string& name = "tmp");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& rel) const { return path_ / rel; }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
  uint64_t peak_rss_bytes = 0;  // the process's peak resident memory (as /usr/bin/time's %M)
};
// Runs nsgraph with the arguments (no shell); captures stdout and stderr.
CommandResult run_nsgraph(const std::vector<std::string>& args);
// Runs any program (argv[0] searched on PATH); captures stdout and stderr.
CommandResult run_program(const std::vector<std::string>& argv);

// A folder produced once and shared by every test process of the build (ctest runs each
// test in its own process): `produce(dir)` fills a fresh folder, which is renamed to
// <build>/test-cache/<name>-<key> when complete; later calls return it as is. `key` must
// change whenever the content would (e.g. a hash of the inputs and of the nsgraph binary).
std::filesystem::path cached_folder(const std::string& name, const std::string& key,
                                    const std::function<void(const std::filesystem::path&)>& produce);
// A key naming the nsgraph binary's build (size and modification time).
std::string nsgraph_build_key();
// samples/synth/tiny.json synthesized (seed 7, 2 threads) once per build and shared by every
// test process: read it, never write into it (copy it first).
std::filesystem::path tiny_release();

void write_text(const std::filesystem::path& path, const std::string& text);
std::string read_text(const std::filesystem::path& path);

}  // namespace nsg::test
