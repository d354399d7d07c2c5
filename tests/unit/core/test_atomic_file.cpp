#include <gtest/gtest.h>

#include <filesystem>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace nsg {

namespace {
size_t count_files(const fs::path& dir) {
  size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}
}  // namespace

TEST(AtomicFile, CommitReplacesTargetAndLeavesNoTemp) {
  test::TempDir dir("atomic");
  write_file_atomic(dir / "sub/out.txt", "first");
  write_file_atomic(dir / "sub/out.txt", "second");
  EXPECT_EQ(read_file(dir / "sub/out.txt"), "second");
  EXPECT_EQ(count_files(dir / "sub"), 1u);
}

TEST(AtomicFile, AbandonedWriterLeavesNothing) {
  test::TempDir dir("atomic");
  {
    AtomicFileWriter w(dir / "out.bin");
    w.write("partial");
    EXPECT_TRUE(fs::exists(w.temp_path()));
  }  // destroyed without commit, as on an exception
  EXPECT_EQ(count_files(dir.path()), 0u);
}

// A deferred file is whole and in place at commit, as an immediate one; its durability
// comes from the folder's flush (a frames export's thousands of records: one syncfs, not
// two fsyncs each). Flushing a folder that is not there is an IoError naming it.
TEST(AtomicFile, DeferredDurabilityIsWholeAtCommitAndFlushedOnce) {
  test::TempDir dir("atomic");
  write_file_atomic(dir / "a/r1.json", "one", Durability::kDeferred);
  AtomicFileWriter w(dir / "a/r2.json", Durability::kDeferred);
  w.write("two");
  w.commit();
  EXPECT_EQ(read_file(dir / "a/r1.json"), "one");
  EXPECT_EQ(read_file(dir / "a/r2.json"), "two");
  EXPECT_EQ(count_files(dir / "a"), 2u);
  EXPECT_NO_THROW(flush_file_system(dir / "a"));
  try {
    flush_file_system(dir / "missing");
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, UnwritableFolderIsAnIoErrorNamingThePath) {
  try {
    write_file_atomic("/proc/nsg-cannot-write/x.txt", "x");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/proc/nsg-cannot-write"), std::string::npos);
  }
}

TEST(Files, ReadMissingFileNamesIt) {
  try {
    read_file("/nonexistent/nsg.json");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/nsg.json");
  }
}

}  // namespace nsg
