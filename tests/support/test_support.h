#pragma once
// Helpers shared by the test binaries: source paths, scratch folders, running the CLI.
#include <filesystem>
#include <string>
#include <vector>

namespace nsg::test {

// Repository root (for samples/, schemas/) and ../shared (golden files).
std::filesystem::path source_dir();
std::filesystem::path shared_dir();
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
};
// Runs nsgraph with the arguments (no shell); captures stdout and stderr.
CommandResult run_nsgraph(const std::vector<std::string>& args);
// Runs any program (argv[0] searched on PATH); captures stdout and stderr.
CommandResult run_program(const std::vector<std::string>& argv);

void write_text(const std::filesystem::path& path, const std::string& text);
std::string read_text(const std::filesystem::path& path);

}  // namespace nsg::test
