// A release, the dataset generated from it and a frames export of that dataset, moved together
// to another folder, are read there by every command: the paths the documents keep to each
// other are relative to the documents. The release moved alone is named with the option that
// finds it (--dataroot).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/metrics/frames_documents.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> generate_args(const fs::path& release, const fs::path& out) {
  std::vector<std::string> args = e2e_generate_args(out);
  for (size_t i = 0; i + 1 < args.size(); ++i)
    if (args[i] == "--dataroot") args[i + 1] = release.string();
  return args;
}

CommandResult frames(const fs::path& dataset, const fs::path& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"frames", "--quiet",    "--dataset", dataset.string(),
                                   "--out",  out.string(), "--overlap", "keep"};
  args.insert(args.end(), extra.begin(), extra.end());
  return run_nsgraph(args);
}

TEST(Relocate, ADatasetMovedWithItsReleaseIsReadByEveryCommand) {
  TempDir dir("relocate");
  const fs::path before = dir / "before";
  const fs::path after = dir / "after";
  fs::create_directories(before);
  fs::copy(e2e_release(), before / "release", fs::copy_options::recursive);
  CommandResult r = run_nsgraph(generate_args(before / "release", before / "dataset"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = frames(before / "dataset", before / "frames");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_json(before / "dataset" / "manifest.json")["inputs"]["dataroot"], "../release");

  fs::rename(before, after);
  EXPECT_EQ(run_nsgraph({"validate", (after / "dataset").string()}).exit_code, 0);
  EXPECT_EQ(run_nsgraph({"stats", (after / "dataset").string()}).exit_code, 0);
  r = run_nsgraph({"preview", (after / "dataset").string(), "--out", (after / "preview").string(), "--max-tiles", "2"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = run_nsgraph({"report", "--dataset", (after / "dataset").string(), "--out", (after / "report").string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = frames(after / "dataset", after / "frames-again");
  EXPECT_EQ(r.exit_code, 0) << r.err;

  // The export moved with the release: its referenced images are found through source.dataroot.
  const metrics::FramesManifest exported = metrics::read_frames_manifest(after / "frames");
  const fs::path release = exported.release_folder();
  EXPECT_EQ(release, after / "release");
  const std::vector<const metrics::FramesListedFile*> listed = exported.records("test");
  ASSERT_FALSE(listed.empty());
  const metrics::FrameRecord record = metrics::read_listed_record(exported, *listed.front(), true);
  ASSERT_FALSE(record.cameras.empty());
  for (const auto& camera : record.cameras)
    EXPECT_TRUE(fs::is_regular_file(release / camera.image_path)) << camera.image_path;

  // The release moved without the dataset: the error says where it looked and what to pass.
  fs::rename(after / "release", dir / "elsewhere");
  r = frames(after / "dataset", after / "frames-lost");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--dataroot"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(after / "frames-lost"));
  r = frames(after / "dataset", after / "frames-found", {"--dataroot", (dir / "elsewhere").string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A manifest written before the path was relative (where generate ran): still found.
TEST(Relocate, AnOlderCwdRelativeDatarootIsStillRead) {
  TempDir dir("relocate-old");
  fs::create_directories(dir / "release");
  EXPECT_EQ(resolve_document_path((dir / "release").string(), dir / "dataset"), dir / "release");
  EXPECT_EQ(resolve_document_path("../release", dir / "dataset"), dir / "release");
  EXPECT_EQ(path_relative_to(dir / "release", dir / "dataset"), "../release");
  EXPECT_EQ(path_relative_to(dir / "release/", dir / "dataset/"), "../release");
  EXPECT_EQ(path_relative_to(dir / "dataset" / "release", dir / "dataset"), "release");
  const fs::path cwd = fs::current_path();
  const std::string from_cwd = fs::relative(dir / "release", cwd).string();
  EXPECT_EQ(resolve_document_path(from_cwd, dir / "nowhere" / "dataset"), fs::path(from_cwd));
}

}  // namespace
}  // namespace nsg::test
