// The done-record's one model: the reader gives back what generate wrote (the writer
// reproduces the file byte for byte), the file is what its schema says, and the reader
// refuses a record that is not a regular file or is beyond its size before reading it.
#include <gtest/gtest.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "generate_fixture.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/pipeline/done_record.h"
#include "nsg/validate/documents.h"
#include "nsg/validate/schema.h"
#include "test_support.h"

namespace nsg::pipeline {
namespace {

namespace fs = std::filesystem;

TEST(DoneRecord, TheReaderGivesBackWhatGenerateWroteAndTheWriterItsBytes) {
  const fs::path file = test::e2e_dataset() / "parts/share-000000-of-000001.json";
  const std::string bytes = read_file(file);
  const DoneRecord r = read_done_record(file);
  EXPECT_TRUE(r.complete);
  EXPECT_EQ(r.share_index, 0);
  EXPECT_EQ(r.share_count, 1);
  EXPECT_EQ(r.config_sha256.size(), 64u);
  ASSERT_FALSE(r.items.empty());
  ASSERT_FALSE(r.plan.empty());
  int shards = 0;
  for (const DoneItem& item : r.items) {
    EXPECT_FALSE(item.files.empty()) << item.id;
    shards += item.kind == "shard" ? 1 : 0;
  }
  EXPECT_GT(shards, 0);
  EXPECT_EQ(done_record_text(r), bytes);
  const Issues issues = validate::validate_against_schema(validate::schema_path("done-record"),
                                                          nlohmann::json::parse(bytes), file.string(), "schema");
  EXPECT_TRUE(issues.empty()) << issues.format();
}

TEST(DoneRecord, SizeAndFileTypeAreCheckedBeforeReading) {
  test::TempDir dir("done-record");
  const fs::path link = dir / "share-000000-of-000001.json";
  fs::create_symlink("/dev/zero", link);
  try {
    read_done_record(link);
    FAIL() << "a link to /dev/zero was read";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), link.string());
    EXPECT_NE(e.expected().find("regular file"), std::string::npos) << e.what();
  }
  const fs::path big = dir / "big.json";
  test::write_text(big, "{}");
  fs::resize_file(big, kMaxDoneRecordBytes + 1);  // sparse: nothing is written
  try {
    read_done_record(big);
    FAIL() << "a record beyond the size limit was read";
  } catch (const ParseError& e) {
    EXPECT_NE(e.expected().find("at most"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_done_record(dir / "absent.json"), IoError);
}

}  // namespace
}  // namespace nsg::pipeline
