// The README's quick start, run as written: its ```sh block after the quick-start marker,
// from a folder laid out like the repository (samples/ and the build's binary), must
// print the ```text block that follows it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "nsg/core/files.h"
#include "test_support.h"

namespace nsg {
namespace {

namespace fs = std::filesystem;

// The body of the first ```<lang> block at or after `from` in `text`.
std::string fenced_block(const std::string& text, size_t from, const std::string& lang, size_t* end = nullptr) {
  const std::string open = "```" + lang + "\n";
  const size_t start = text.find(open, from);
  if (start == std::string::npos) return "";
  const size_t body = start + open.size();
  const size_t close = text.find("\n```", body);
  if (end != nullptr) *end = close;
  return close == std::string::npos ? "" : text.substr(body, close - body + 1);
}

TEST(ReadmeQuickStart, RunsAsWrittenAndPrintsWhatItSays) {
  const std::string readme = read_file(test::source_dir() / "README.md");
  const size_t marker = readme.find("<!-- quick start:");
  ASSERT_NE(marker, std::string::npos) << "no quick-start marker in README.md";
  size_t after = 0;
  const std::string script = fenced_block(readme, marker, "sh", &after);
  const std::string expected = fenced_block(readme, after, "text");
  ASSERT_FALSE(script.empty());
  ASSERT_FALSE(expected.empty());
  // A folder like the repository's root: samples/ and build/tools/nsgraph/nsgraph.
  test::TempDir root("readme-quickstart");
  fs::create_directory_symlink(test::source_dir() / "samples", root / "samples");
  fs::create_directories(root / "build/tools/nsgraph");
  fs::create_symlink(test::nsgraph_exe(), root / "build/tools/nsgraph/nsgraph");
  const test::CommandResult r =
      test::run_program({"bash", "-c", "set -euo pipefail\ncd '" + root.path().string() + "'\n" + script});
  ASSERT_EQ(r.exit_code, 0) << "the quick start failed:\n" << script << "\nstderr:\n" << r.err;
  EXPECT_NE(r.out.find(expected), std::string::npos) << "the README says it prints:\n"
                                                     << expected << "\nit printed:\n"
                                                     << r.out;
}

}  // namespace
}  // namespace nsg
