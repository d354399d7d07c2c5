// The tables and sensor files of the real release (docs/nuscenes-input.md "Tables and
// sensor files"): what the devkit loads loads here (empty links, non-camera records
// without intrinsics, dropped sweeps, empty annotation tables, the lidarseg category.json),
// and what it cannot load (truncated or missing sweeps, a missing version folder) stops
// with an error naming the file.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nuscenes_fixture.h"

namespace nsg::nuscenes {
namespace {

using nlohmann::ordered_json;
using test::FixtureCopy;

Token tok(const std::string& s) { return Token::from_string(s); }

ordered_json read_table_json(const FixtureCopy& copy, const std::string& name) {
  return ordered_json::parse(test::read_text(copy.table(name)));
}
void write_table_json(const FixtureCopy& copy, const std::string& name, const ordered_json& j) {
  test::write_text(copy.table(name), j.dump(1));
}

Database load(const FixtureCopy& copy) { return Database::load(copy.root(), test::kFixtureVersion); }

TEST(RealTableQuirks, EmptyLinksAndTheFirstKeyFrame) {
  FixtureCopy copy;
  const Database db = load(copy);
  const Sample& first = db.sample.get(tok(test::kSample1));
  EXPECT_TRUE(first.prev_token.empty());
  EXPECT_EQ(first.prev, kNoIndex);
  EXPECT_EQ(db.sample.get(tok(test::kSample2)).next, kNoIndex);
  EXPECT_EQ(db.sample_data.get(tok(test::kSd1)).prev, kNoIndex);
  EXPECT_EQ(db.scene[0].first_sample, db.sample.find(tok(test::kSample1)));
}

TEST(RealTableQuirks, NonCameraRecordsHaveNoIntrinsicsAndZeroSize) {
  FixtureCopy copy;
  const Database db = load(copy);
  EXPECT_FALSE(db.calibrated_sensor.get(tok(test::kCsLidar)).camera_intrinsic.has_value());
  ASSERT_TRUE(db.calibrated_sensor.get(tok(test::kCsCam)).camera_intrinsic.has_value());
  const SampleData& lidar = db.sample_data.get(tok(test::kSd1));
  EXPECT_EQ(lidar.width, 0);
  EXPECT_EQ(lidar.height, 0);
  EXPECT_EQ(lidar.modality, Modality::kLidar);
}

// 4 camera sweeps between two key frames (one dropped), each linked to the nearest
// following sample: the channels of the scene differ in count (LiDAR 3, camera 6).
TEST(RealTableQuirks, DroppedSweepsAndUnevenChannels) {
  FixtureCopy copy;
  ordered_json sd = read_table_json(copy, "sample_data");
  ordered_json poses = read_table_json(copy, "ego_pose");
  const ordered_json key1 = sd[3], key2 = sd[4];  // CAM_FRONT key frames of samples 1 and 2
  std::vector<std::string> chain{key1["token"]};
  for (int i = 1; i <= 4; ++i) {
    ordered_json sweep = key1;
    sweep["token"] = "5d0000000000000000000000000000c" + std::to_string(i);
    sweep["ego_pose_token"] = sweep["token"];
    sweep["sample_token"] = test::kSample2;
    sweep["is_key_frame"] = false;
    sweep["timestamp"] = key1["timestamp"].get<int64_t>() + 100000 * i;
    sweep["filename"] = "sweeps/CAM_FRONT/c" + std::to_string(i) + ".jpg";
    ordered_json pose = poses[3];
    pose["token"] = sweep["token"];
    pose["timestamp"] = sweep["timestamp"];
    poses.push_back(pose);
    chain.push_back(sweep["token"]);
    sd.push_back(sweep);
  }
  chain.push_back(key2["token"]);
  for (ordered_json& r : sd) {  // prev/next along the chain
    const auto at = std::find(chain.begin(), chain.end(), r["token"].get<std::string>());
    if (at == chain.end()) continue;
    r["prev"] = at == chain.begin() ? "" : *(at - 1);
    r["next"] = at + 1 == chain.end() ? "" : *(at + 1);
  }
  write_table_json(copy, "sample_data", sd);
  write_table_json(copy, "ego_pose", poses);

  const Database db = load(copy);
  size_t lidar = 0, camera = 0;
  for (const SampleData& r : db.sample_data) (r.modality == Modality::kCamera ? camera : lidar) += 1;
  EXPECT_EQ(lidar, 3u);
  EXPECT_EQ(camera, 6u);
  const Index sample2 = db.sample.find(tok(test::kSample2));
  const SampleData& sweep = db.sample_data.get(tok("5d0000000000000000000000000000c1"));
  EXPECT_FALSE(sweep.is_key_frame);
  EXPECT_EQ(sweep.sample, sample2);
  EXPECT_EQ(db.sample_data[sweep.prev].token, tok(test::kSd4));
  EXPECT_EQ(db.key_frame(sample2, "CAM_FRONT"), db.sample_data.find(tok(test::kSd5)));
  EXPECT_EQ(db.sample_data.get(tok(test::kSd5)).prev, db.sample_data.find(tok("5d0000000000000000000000000000c4")));
}

// The test split: instance and sample_annotation are empty arrays.
TEST(RealTableQuirks, EmptyAnnotationTablesOfTheTestSplit) {
  FixtureCopy copy;
  test::write_text(copy.table("instance"), "[]");
  test::write_text(copy.table("sample_annotation"), "[]\n");
  const Database db = load(copy);
  EXPECT_TRUE(db.instance.empty());
  EXPECT_TRUE(db.sample_annotation.empty());
  EXPECT_EQ(db.sample.size(), 2u);
  for (const Sample& s : db.sample) EXPECT_TRUE(s.anns.empty());
  EXPECT_EQ(db.category.size(), 2u);
}

// nuScenes-lidarseg ships a 32-record category.json with an "index" per record; the devkit
// requires it once lidarseg.json exists.
TEST(RealTableQuirks, LidarsegCategoryJsonWithIndex) {
  FixtureCopy copy;
  ordered_json categories = read_table_json(copy, "category");
  for (int i = 0; i < 32; ++i) {
    if (i == 2 || i == 17) continue;  // the fixture's pedestrian and car
    char token[33];
    std::snprintf(token, sizeof token, "ca7000000000000000000000000001%02d", i);
    categories.push_back(
        {{"token", token}, {"name", "lidarseg.class" + std::to_string(i)}, {"description", ""}, {"index", i}});
  }
  write_table_json(copy, "category", categories);
  test::write_text(copy.table("lidarseg"), "[]");
  const Database db = load(copy);
  ASSERT_EQ(db.category.size(), 32u);
  EXPECT_EQ(db.category.get(tok(test::kCar)).index, 17);
  EXPECT_EQ(db.category.get(tok("ca700000000000000000000000000131")).index, 31);

  categories[5].erase("index");
  write_table_json(copy, "category", categories);
  const std::string token = categories[5]["token"];
  test::expect_error<DataError>([&] { (void)load(copy); }, "category.json", {token, "\"index\"", "lidarseg.json"});
  std::filesystem::remove(copy.table("lidarseg"));  // without lidarseg the index is optional
  EXPECT_FALSE(load(copy).category.get(tok(token)).index.has_value());
}

TEST(RealTableQuirks, MissingVersionFolderNamesTheFoldersFound) {
  FixtureCopy copy;
  test::expect_error<IoError>(
      [&] { (void)Database::load(copy.root(), "v1.0-trainval"); }, "v1.0-trainval",
      {"no v1.0-trainval/ under " + copy.root().string(), "found: v1.0-mini (use --version v1.0-mini)"});
  test::write_text(copy.root() / "v1.0-test" / "category.json", "[]");
  std::filesystem::create_directories(copy.root() / "v0.9-notes");  // no category.json: not a release
  test::expect_error<IoError>([&] { (void)Database::load(copy.root(), "v1.0-trainval"); }, "v1.0-trainval",
                              {"found: v1.0-mini, v1.0-test (pick one with --version)"});
  test::TempDir empty("no-release");
  test::expect_error<IoError>([&] { (void)Database::load(empty.path(), "v1.0-trainval"); }, "v1.0-trainval",
                              {"found no release folder"});
}

// Download damage (#233) and unextracted archives (#756): errors naming the file.
TEST(RealTableQuirks, TruncatedAndMissingSweepsNameTheFile) {
  FixtureCopy copy;
  const Database db = load(copy);
  const Index sd = db.sample_data.find(tok(test::kSd1));
  const std::filesystem::path file = db.file_path(db.sample_data[sd]);
  ASSERT_EQ(load_sweep_global(db, sd).size(), 3u);  // 60 bytes: 3 points
  std::filesystem::resize_file(file, 52);
  test::expect_error<ParseError>([&] { (void)load_sweep_global(db, sd); }, file.string(),
                                 {"size 52 bytes", "a multiple of 20 bytes"});
  std::filesystem::remove(file);
  test::expect_error<IoError>([&] { (void)load_sweep_global(db, sd); }, file.string(), {"extracted"});
}

}  // namespace
}  // namespace nsg::nuscenes
