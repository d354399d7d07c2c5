// Malformed releases: each case breaks one file of a copy of the fixture and asserts the
// exception type and that the message names the file, the record and the field.
#include <gtest/gtest.h>

#include <filesystem>

#include "nsg/nuscenes/database.h"
#include "nuscenes_fixture.h"

namespace nsg::nuscenes {
namespace {

using test::expect_error;
using test::FixtureCopy;

void load(const FixtureCopy& f) { Database::load(f.root(), test::kFixtureVersion); }

TEST(Malformed, TruncatedTable) {
  FixtureCopy f;
  const std::string text = test::read_text(f.table("sample_data"));
  test::write_text(f.table("sample_data"), text.substr(0, text.size() / 2));
  expect_error<ParseError>([&] { load(f); }, "sample_data.json", {"record", "truncated"});
}

TEST(Malformed, WrongType) {
  FixtureCopy f;
  f.replace_in_table("ego_pose", "\"timestamp\": 1532402927647951", "\"timestamp\": \"1532402927647951\"");
  expect_error<ParseError>([&] { load(f); }, "ego_pose.json", {"record 0", test::kSd1, "\"timestamp\"", "integer"});
}

// Key order is free: a bad value before the record's "token" key still names the token
// (found by scanning the record's text on the error path).
TEST(Malformed, WrongTypeBeforeTheTokenKey) {
  FixtureCopy f;
  f.replace_in_table("sample", "\"token\": \"" + test::kSample2 + "\"",
                     "\"timestamp\": [1, {\"token\": \"x\"}], \"token\": \"" + test::kSample2 + "\"");
  expect_error<ParseError>([&] { load(f); }, "sample.json", {"record 1", test::kSample2, "\"timestamp\"", "integer"});
}

TEST(Malformed, FloatWhereIntegerExpected) {
  FixtureCopy f;
  f.replace_in_table("sample_data", "\"height\": 900", "\"height\": 900.5");
  expect_error<ParseError>([&] { load(f); }, "sample_data.json", {test::kSd4, "\"height\"", "integer"});
}

TEST(Malformed, MissingKey) {
  FixtureCopy f;
  f.replace_in_table("sample_data", "\"fileformat\": \"pcd\",\n", "");
  expect_error<ParseError>([&] { load(f); }, "sample_data.json", {test::kSd1, "fileformat", "missing"});
}

TEST(Malformed, RepeatedKey) {
  FixtureCopy f;
  f.replace_in_table("sample", "\"prev\": \"\",", "\"prev\": \"\", \"prev\": \"\",");
  expect_error<ParseError>([&] { load(f); }, "sample.json", {test::kSample1, "\"prev\"", "once"});
}

TEST(Malformed, DanglingToken) {
  FixtureCopy f;
  f.replace_in_table("sample_annotation", "\"instance_token\": \"" + test::kInstance,
                     "\"instance_token\": \"1a0000000000000000000000000000ff");
  expect_error<DataError>([&] { load(f); }, "sample_annotation.json",
                          {test::kAnn1, "instance_token", "1a0000000000000000000000000000ff", "instance.json"});
}

TEST(Malformed, DanglingCalibratedSensorSensor) {
  FixtureCopy f;
  f.replace_in_table("calibrated_sensor", "\"sensor_token\": \"" + test::kLidarSensor,
                     "\"sensor_token\": \"dc8b396651c05aedbb9cdaae573bb500");
  expect_error<DataError>([&] { load(f); }, "calibrated_sensor.json", {test::kCsLidar, "sensor_token"});
}

TEST(Malformed, DanglingInstanceCategory) {
  FixtureCopy f;
  f.replace_in_table("instance", "\"category_token\": \"" + test::kCar,
                     "\"category_token\": \"ca700000000000000000000000000009");
  expect_error<DataError>([&] { load(f); }, "instance.json", {test::kInstance, "category_token"});
}

TEST(Malformed, NaNInPose) {
  FixtureCopy f;
  f.replace_in_table("ego_pose", "100.0", "NaN");
  expect_error<ParseError>([&] { load(f); }, "ego_pose.json", {test::kSd1, "\"translation\"", "NaN"});
}

TEST(Malformed, InfinityInAnnotation) {
  FixtureCopy f;
  f.replace_in_table("sample_annotation", "110.5", "1e999");
  expect_error<ParseError>([&] { load(f); }, "sample_annotation.json", {test::kAnn1, "\"translation\""});
}

TEST(Malformed, WrongQuaternionArity) {
  FixtureCopy f;
  f.replace_in_table("ego_pose", "\"rotation\": [\n1.0,", "\"rotation\": [\n");
  expect_error<ParseError>([&] { load(f); }, "ego_pose.json", {test::kSd2, "\"rotation\"", "4 finite numbers"});
}

TEST(Malformed, DuplicateToken) {
  FixtureCopy f;
  f.replace_in_table("sample", "\"token\": \"" + test::kSample2, "\"token\": \"" + test::kSample1);
  expect_error<ParseError>([&] { load(f); }, "sample.json", {"record 1", test::kSample1, "unique"});
}

TEST(Malformed, InvalidTokenText) {
  FixtureCopy f;
  f.replace_in_table("scene", "\"token\": \"" + test::kScene, "\"token\": \"5CE00000000000000000000000000001");
  expect_error<ParseError>([&] { load(f); }, "scene.json", {"record 0", "32 lowercase hex"});
}

TEST(Malformed, TrailingContent) {
  FixtureCopy f;
  test::write_text(f.table("log"), test::read_text(f.table("log")) + " ]");
  expect_error<ParseError>([&] { load(f); }, "log.json", {"end of file"});
}

TEST(Malformed, NotAnArray) {
  FixtureCopy f;
  test::write_text(f.table("attribute"), "{\"token\": \"x\"}");
  expect_error<ParseError>([&] { load(f); }, "attribute.json", {"array"});
}

TEST(Malformed, MissingTableFile) {
  FixtureCopy f;
  std::filesystem::remove(f.table("instance"));
  expect_error<IoError>([&] { load(f); }, "instance.json", {"missing"});
}

TEST(Malformed, MissingMapPng) {
  FixtureCopy f;
  std::filesystem::remove(f.root() / "maps" / (test::kMap + ".png"));
  expect_error<IoError>([&] { load(f); }, test::kMap + ".png", {"map.json", test::kMap});
  // The check can be switched off (contents are read lazily anyway).
  LoadOptions options;
  options.check_map_files = false;
  EXPECT_NO_THROW(Database::load(f.root(), test::kFixtureVersion, options));
}

TEST(Malformed, LogNotInAnyMap) {
  FixtureCopy f;
  f.replace_in_table("map", "\"" + test::kLog + "\"", "");
  expect_error<DataError>([&] { load(f); }, "log.json", {test::kLog, "map.json"});
}

TEST(Malformed, TwoKeyFramesOfOneChannel) {
  FixtureCopy f;
  // The LIDAR sweep becomes a second key frame of sample 2.
  f.replace_in_table("sample_data", "\"is_key_frame\": false", "\"is_key_frame\": true");
  expect_error<DataError>([&] { load(f); }, "sample_data.json", {test::kSd3, "LIDAR_TOP", test::kSample2});
}

TEST(Malformed, MissingDataroot) {
  expect_error<IoError>([&] { Database::load("/nonexistent/nsg-dataroot", "v1.0-mini"); }, "/nonexistent/nsg-dataroot",
                        {"dataroot"});
}

}  // namespace
}  // namespace nsg::nuscenes

namespace nsg::nuscenes {
namespace {

// A sample_data filename may not climb out of the dataroot: the release still loads (the
// devkit's would), and reading that record's file is refused by name.
TEST(Malformed, FilenameOutsideTheDatarootIsRefusedByName) {
  test::FixtureCopy f;
  f.replace_in_table("sample_data",
                     "\"samples/LIDAR_TOP/n015-2018-07-24-11-22-45+0800__LIDAR_TOP__1532402927647951.pcd.bin\"",
                     "\"../../../etc/hostname\"");
  const Database db = Database::load(f.root(), test::kFixtureVersion);
  const Index sd = db.sample_data.find(*Token::parse(test::kSd1));
  ASSERT_NE(sd, kNoIndex);
  test::expect_error<DataError>([&] { db.file_path(db.sample_data[sd]); }, "sample_data.json",
                                {test::kSd1, "inside the dataroot", "../../../etc/hostname"});
  EXPECT_EQ(db.file_path(db.sample_data[sd == 0 ? 1 : 0]).string().rfind(f.root().string(), 0), 0u);
}

}  // namespace
}  // namespace nsg::nuscenes
