// The output-folder owner: names from data, paths that stay inside, links never followed,
// and removal of an earlier output limited to the files a document of ours lists.
#include <gtest/gtest.h>

#include <filesystem>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/output_folder.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace nsg {

TEST(SafeName, AcceptsNamesOfRealReleasesAndRefusesPathsNamingTheRecord) {
  for (const std::string ok :
       {"scene-0061", "CAM_FRONT", "boston-seaport", "singapore-onenorth-test-000001", "a.b", "..a", "x y"})
    EXPECT_EQ(safe_name(ok, "scene.json", "scene"), ok);
  const std::vector<std::string> refused = {
      "", ".", "..", "../escaped", "a/b", "/abs", "a\\b", std::string("a\0b", 3), "tab\t", std::string(256, 'x')};
  for (const std::string& bad : refused) {
    try {
      safe_name(bad, "scene.json", "scene 'x' (token t1)");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const DataError& e) {
      EXPECT_EQ(e.file(), "scene.json");
      EXPECT_EQ(e.record(), "scene 'x' (token t1)");
      EXPECT_NE(e.expected().find("one file name"), std::string::npos) << e.what();
    }
  }
}

TEST(OutputFolder, PathsStayInsideAndNoLinkIsFollowed) {
  test::TempDir dir("outfolder");
  test::TempDir outside("outfolder-outside");
  const OutputFolder out(dir / "out");
  out.write("a/b/c.txt", "x");
  EXPECT_EQ(read_file(dir / "out/a/b/c.txt"), "x");
  EXPECT_THROW(out.path("../escaped.txt"), ConfigError);
  EXPECT_THROW(out.path("/etc/passwd"), ConfigError);
  EXPECT_THROW(out.path(""), ConfigError);
  // A link inside the folder, to a folder outside: neither written through nor into.
  fs::create_directory_symlink(outside.path(), dir / "out/img");
  EXPECT_THROW(out.write("img/p.png", "y"), DataError);
  EXPECT_TRUE(fs::is_empty(outside.path()));
  // A file where a folder is needed.
  EXPECT_THROW(out.path("a/b/c.txt/d"), DataError);
}

TEST(OutputFolder, RemovesOnlyListedFilesAndRefusesBeforeRemovingAnything) {
  test::TempDir dir("outfolder");
  test::TempDir outside("outfolder-outside");
  const OutputFolder out(dir.path());
  out.write("shards/train-000000.tar", "t");
  out.write("shards/test-000000.tar", "t");
  out.write("shards/user-notes.txt", "mine");
  out.write("keep.txt", "not in an owned folder");
  write_file_atomic(outside / "precious.txt", "p");
  const std::set<std::string> listed = {"shards/train-000000.tar", "shards/test-000000.tar",
                                        "../" + outside.path().filename().string() + "/precious.txt"};
  try {
    out.remove_listed(listed, {"shards"}, "the manifest");
    ADD_FAILURE() << "removed a file it did not list";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("shards/user-notes.txt"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(dir / "shards/train-000000.tar"));  // nothing removed before the refusal
  fs::remove(dir / "shards/user-notes.txt");
  // A temp file of our writers is ours; a listed path outside is never touched.
  out.write("shards/x.tar.tmp-12-3", "");
  EXPECT_EQ(out.remove_listed(listed, {"shards", "maps"}, "the manifest"), 3);
  EXPECT_FALSE(fs::exists(dir / "shards"));
  EXPECT_TRUE(fs::exists(dir / "keep.txt"));
  EXPECT_TRUE(fs::exists(outside / "precious.txt"));
}

TEST(OutputFolder, ALinkedOwnedFolderIsRefusedNotEntered) {
  test::TempDir dir("outfolder");
  test::TempDir outside("outfolder-outside");
  write_file_atomic(outside / "lanes.geojson", "{}");
  fs::create_directory_symlink(outside.path(), dir / "maps");
  const OutputFolder out(dir.path());
  EXPECT_THROW(out.remove_listed({"maps/lanes.geojson"}, {"maps"}, "the manifest"), DataError);
  EXPECT_TRUE(fs::exists(outside / "lanes.geojson"));
}

TEST(OutputFolder, OutMayNotBeOrHoldAnInput) {
  test::TempDir dir("outfolder");
  fs::create_directories(dir / "reports/sub");
  EXPECT_THROW(refuse_out_over_input(dir / "reports", dir / "reports", "--leaderboard"), ConfigError);
  EXPECT_THROW(refuse_out_over_input(dir / "reports/./", dir / "reports", "--leaderboard"), ConfigError);
  EXPECT_THROW(refuse_out_over_input(dir.path(), dir / "reports", "--leaderboard"), ConfigError);
  EXPECT_NO_THROW(refuse_out_over_input(dir / "reports/page", dir / "reports", "--leaderboard"));
  EXPECT_NO_THROW(refuse_out_over_input(dir / "elsewhere", dir / "reports", "--leaderboard"));
}

TEST(OutputFolder, TempNamesAreOursOnly) {
  EXPECT_TRUE(is_temp_name("manifest.json.tmp-123-0"));
  EXPECT_FALSE(is_temp_name("manifest.json"));
  EXPECT_FALSE(is_temp_name(".tmp-1-2"));
  EXPECT_FALSE(is_temp_name("notes.tmp-a-2"));
}

}  // namespace nsg
