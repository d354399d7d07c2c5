// Every table of the fixture release parsed with its values; links resolved; derived
// indices computed like the devkit.
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/core/strings.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/tables.h"
#include "nuscenes_fixture.h"

namespace nsg::nuscenes {
namespace {

using test::fixture_root;
using test::kFixtureVersion;

Token T(const std::string& s) { return Token::from_string(s); }

class FixtureDb : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { db_ = new Database(Database::load(fixture_root(), kFixtureVersion)); }
  static void TearDownTestSuite() {
    delete db_;
    db_ = nullptr;
  }
  static const Database& db() { return *db_; }
  static Database* db_;
};
Database* FixtureDb::db_ = nullptr;

const double kC45 = std::cos(M_PI / 4);

TEST(Token, ParsesHexShortAndEmpty) {
  const Token hex = Token::from_string("0123456789abcdef0123456789abcdef");
  EXPECT_EQ(hex.kind(), Token::Kind::kHex32);
  EXPECT_EQ(hex.str(), "0123456789abcdef0123456789abcdef");
  EXPECT_TRUE(Token::parse("").value().empty());
  EXPECT_FALSE(Token::parse("0123456789ABCDEF0123456789abcdef"));  // uppercase
  EXPECT_FALSE(Token::parse("4"));                                 // short only when allowed
  EXPECT_EQ(Token::parse("4", true).value().str(), "4");
  EXPECT_NE(Token::from_string("4"), Token::from_string("3"));
  EXPECT_FALSE(Token::parse("0123456789abcdef0123456789abcde"));  // 31 chars
}

// Every byte value at every position: only [0-9a-f] parse as a 32-char token, and what
// parses prints back the same (the vectorized parser against the definition).
TEST(Token, AcceptsExactlyLowercaseHexAtEveryPosition) {
  const std::string valid = "0f1e2d3c4b5a69788796a5b4c3d2e1f0";
  for (size_t pos = 0; pos < 32; ++pos) {
    for (int byte = 0; byte < 256; ++byte) {
      std::string text = valid;
      text[pos] = static_cast<char>(byte);
      const bool hex = (byte >= '0' && byte <= '9') || (byte >= 'a' && byte <= 'f');
      const std::optional<Token> t = Token::parse(text);
      ASSERT_EQ(t.has_value(), hex) << "position " << pos << ", byte " << byte;
      if (hex) {
        ASSERT_EQ(t->kind(), Token::Kind::kHex32);
        ASSERT_EQ(t->str(), text);
      }
    }
  }
}

TEST(Token, IndexFindsEveryRowAndReportsDuplicates) {
  std::vector<Token> tokens;
  for (int i = 0; i < 1000; ++i) tokens.push_back(Token::from_string(strprintf("%032x", i * 7919)));
  TokenIndex index;
  auto at = [&](size_t i) -> const Token& { return tokens[i]; };
  EXPECT_EQ(index.build(tokens.size(), at), kNoIndex);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(index.find(tokens[i], at), i);
  EXPECT_EQ(index.find(Token::from_string(strprintf("%032x", 3)), at), kNoIndex);
  tokens.push_back(tokens[10]);
  EXPECT_EQ(index.build(tokens.size(), at), 1000);
}

TEST_F(FixtureDb, TableSizes) {
  EXPECT_EQ(db().category.size(), 2u);
  EXPECT_EQ(db().attribute.size(), 2u);
  EXPECT_EQ(db().visibility.size(), 4u);
  EXPECT_EQ(db().instance.size(), 1u);
  EXPECT_EQ(db().sensor.size(), 2u);
  EXPECT_EQ(db().calibrated_sensor.size(), 2u);
  EXPECT_EQ(db().ego_pose.size(), 5u);
  EXPECT_EQ(db().log.size(), 1u);
  EXPECT_EQ(db().scene.size(), 1u);
  EXPECT_EQ(db().sample.size(), 2u);
  EXPECT_EQ(db().sample_data.size(), 5u);
  EXPECT_EQ(db().sample_annotation.size(), 2u);
  EXPECT_EQ(db().map.size(), 1u);
}

TEST_F(FixtureDb, CategoryAttributeVisibility) {
  const Category& car = db().category.get(T(test::kCar));
  EXPECT_EQ(car.name, "vehicle.car");
  EXPECT_EQ(car.description, "Vehicle designed primarily for personal use.");
  EXPECT_EQ(car.index, 17);
  EXPECT_EQ(db().category[1].name, "human.pedestrian.adult");
  EXPECT_EQ(db().attribute.get(T(test::kMoving)).name, "vehicle.moving");
  EXPECT_EQ(db().attribute[1].description, "The human is standing.");
  const Visibility& v4 = db().visibility.get(T("4"));
  EXPECT_EQ(v4.level, "v80-100");
  EXPECT_EQ(db().visibility.find(T("1")), 0);
}

TEST_F(FixtureDb, SensorAndCalibratedSensor) {
  const Sensor& lidar = db().sensor.get(T(test::kLidarSensor));
  EXPECT_EQ(lidar.channel, "LIDAR_TOP");
  EXPECT_EQ(lidar.modality, Modality::kLidar);
  EXPECT_EQ(db().sensor.get(T(test::kCamSensor)).modality, Modality::kCamera);
  const CalibratedSensor& cs = db().calibrated_sensor.get(T(test::kCsLidar));
  EXPECT_EQ(cs.sensor, db().sensor.find(T(test::kLidarSensor)));
  EXPECT_EQ(cs.translation, (Vec3{1.0, 0.0, 2.0}));
  EXPECT_DOUBLE_EQ(cs.rotation.w, kC45);
  EXPECT_DOUBLE_EQ(cs.rotation.z, kC45);
  EXPECT_FALSE(cs.camera_intrinsic.has_value());
  const CalibratedSensor& cam = db().calibrated_sensor.get(T(test::kCsCam));
  ASSERT_TRUE(cam.camera_intrinsic.has_value());
  EXPECT_DOUBLE_EQ((*cam.camera_intrinsic)[0][0], 1266.417203046554);
  EXPECT_DOUBLE_EQ((*cam.camera_intrinsic)[1][2], 491.50706579294757);
  EXPECT_DOUBLE_EQ((*cam.camera_intrinsic)[2][2], 1.0);
  EXPECT_DOUBLE_EQ(cam.rotation.x, -0.5030316162024876);  // [w, x, y, z] order kept
  EXPECT_DOUBLE_EQ(cam.translation[2], 1.51095763913);
}

TEST_F(FixtureDb, EgoPoseLogMapScene) {
  const EgoPose& p = db().ego_pose.get(T(test::kSd3));
  EXPECT_EQ(p.timestamp_us, 1532402928147847);
  EXPECT_EQ(p.translation, (Vec3{102.5, 200.25, 0.0}));
  EXPECT_EQ(p.rotation.w, 0.0);
  EXPECT_EQ(p.rotation.z, 1.0);
  const Log& log = db().log[0];
  EXPECT_EQ(log.logfile, "n015-2018-07-24-11-22-45+0800");
  EXPECT_EQ(log.vehicle, "n015");
  EXPECT_EQ(log.date_captured, "2018-07-24");
  EXPECT_EQ(log.location, "boston-seaport");
  EXPECT_EQ(log.map, 0);  // derived
  const Map& map = db().map[0];
  EXPECT_EQ(map.token.str(), test::kMap);
  EXPECT_EQ(map.category, "semantic_prior");
  EXPECT_EQ(map.filename, "maps/" + test::kMap + ".png");
  ASSERT_EQ(map.logs.size(), 1u);
  EXPECT_EQ(map.logs[0], 0);
  const Scene& scene = db().scene[0];
  EXPECT_EQ(scene.name, "scene-0061");
  EXPECT_EQ(scene.description, "Parked truck, construction, intersection");
  EXPECT_EQ(scene.nbr_samples, 2);
  EXPECT_EQ(scene.log, 0);
  EXPECT_EQ(scene.first_sample, db().sample.find(T(test::kSample1)));
  EXPECT_EQ(scene.last_sample, db().sample.find(T(test::kSample2)));
  EXPECT_EQ(db().map_of_scene(0), 0);
}

TEST_F(FixtureDb, SampleLinksAndDerivedData) {
  const Index s1 = db().sample.find(T(test::kSample1)), s2 = db().sample.find(T(test::kSample2));
  EXPECT_EQ(db().sample[s1].timestamp_us, 1532402927647951);
  EXPECT_EQ(db().sample[s1].prev, kNoIndex);
  EXPECT_EQ(db().sample[s1].next, s2);
  EXPECT_EQ(db().sample[s2].prev, s1);
  EXPECT_EQ(db().sample[s2].scene, 0);
  // sample.data: one key frame per channel, computed (not read).
  EXPECT_EQ(db().key_frame(s1, "LIDAR_TOP"), db().sample_data.find(T(test::kSd1)));
  EXPECT_EQ(db().key_frame(s1, "CAM_FRONT"), db().sample_data.find(T(test::kSd4)));
  EXPECT_EQ(db().key_frame(s2, "LIDAR_TOP"), db().sample_data.find(T(test::kSd3)));  // not the sweep
  EXPECT_EQ(db().key_frame(s2, "RADAR_FRONT"), kNoIndex);
  EXPECT_EQ(db().sample[s1].data.size(), 2u);
  ASSERT_EQ(db().sample[s1].anns.size(), 1u);
  EXPECT_EQ(db().sample_annotation[db().sample[s1].anns[0]].token.str(), test::kAnn1);
}

TEST_F(FixtureDb, SampleData) {
  const Index i = db().sample_data.find(T(test::kSd2));
  const SampleData& sd = db().sample_data[i];
  EXPECT_EQ(sd.sample, db().sample.find(T(test::kSample2)));  // sweeps point to the next sample
  EXPECT_EQ(sd.ego_pose, db().ego_pose.find(T(test::kSd2)));
  EXPECT_EQ(sd.calibrated_sensor, db().calibrated_sensor.find(T(test::kCsLidar)));
  EXPECT_EQ(sd.timestamp_us, 1532402927897951);
  EXPECT_EQ(sd.fileformat, "pcd");
  EXPECT_FALSE(sd.is_key_frame);
  EXPECT_EQ(sd.height, 0);
  EXPECT_EQ(sd.filename, "sweeps/LIDAR_TOP/n015-2018-07-24-11-22-45+0800__LIDAR_TOP__1532402927897951.pcd.bin");
  EXPECT_EQ(sd.prev, db().sample_data.find(T(test::kSd1)));
  EXPECT_EQ(sd.next, db().sample_data.find(T(test::kSd3)));
  EXPECT_EQ(db().channel(sd), "LIDAR_TOP");
  EXPECT_EQ(sd.modality, Modality::kLidar);
  const SampleData& cam = db().sample_data.get(T(test::kSd4));
  EXPECT_EQ(cam.width, 1600);
  EXPECT_EQ(cam.height, 900);
  EXPECT_EQ(cam.fileformat, "jpg");
  EXPECT_TRUE(cam.is_key_frame);
  EXPECT_EQ(cam.modality, Modality::kCamera);
  EXPECT_EQ(db().channel(cam), "CAM_FRONT");
  EXPECT_EQ(cam.next_token.str(), test::kSd5);
  EXPECT_EQ(db().file_path(cam), fixture_root() / cam.filename);
}

TEST_F(FixtureDb, InstanceAndAnnotations) {
  const Instance& inst = db().instance[0];
  EXPECT_EQ(inst.category, db().category.find(T(test::kCar)));
  EXPECT_EQ(inst.nbr_annotations, 2);
  EXPECT_EQ(inst.first_annotation, db().sample_annotation.find(T(test::kAnn1)));
  EXPECT_EQ(inst.last_annotation, db().sample_annotation.find(T(test::kAnn2)));
  const SampleAnnotation& a = db().sample_annotation.get(T(test::kAnn1));
  EXPECT_EQ(a.sample, db().sample.find(T(test::kSample1)));
  EXPECT_EQ(a.instance, 0);
  EXPECT_EQ(a.visibility, db().visibility.find(T("4")));
  ASSERT_EQ(a.attributes.size(), 1u);
  EXPECT_EQ(a.attributes[0], db().attribute.find(T(test::kMoving)));
  EXPECT_EQ(a.translation, (Vec3{110.5, 205.25, 1.0}));
  EXPECT_EQ(a.size, (Vec3{1.9, 4.5, 1.6}));  // [width, length, height]
  EXPECT_EQ(a.rotation.w, 1.0);
  EXPECT_EQ(a.num_lidar_pts, 42);
  EXPECT_EQ(a.num_radar_pts, 3);
  EXPECT_EQ(a.category, db().category.find(T(test::kCar)));  // derived through the instance
  const SampleAnnotation& b = db().sample_annotation.get(T(test::kAnn2));
  EXPECT_TRUE(b.visibility_token.empty());
  EXPECT_EQ(b.visibility, kNoIndex);
  EXPECT_TRUE(b.attributes.empty());
  EXPECT_EQ(b.prev, db().sample_annotation.find(T(test::kAnn1)));
  EXPECT_EQ(b.next, kNoIndex);
}

TEST(Tables, KeysInAnyOrderAndUnknownKeysIgnored) {
  test::TempDir dir("keys");
  test::write_text(dir / "category.json",
                   "[{\"index\": 3, \"description\": \"d\", \"extra\": {\"a\": [1, 2]}, \"name\": \"animal\", "
                   "\"token\": \"" +
                       test::kCar + "\"},\n{\"name\":\"n\",\"token\":\"" + test::kPed + "\",\"description\":\"\"}]");
  const std::vector<Category> rows = read_table<Category>(dir / "category.json");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].name, "animal");
  EXPECT_EQ(rows[0].index, 3);
  EXPECT_EQ(rows[0].token.str(), test::kCar);
  EXPECT_FALSE(rows[1].index.has_value());
}

TEST(Tables, EmptyTableAndEscapedStrings) {
  test::TempDir dir("empty");
  test::write_text(dir / "sample_annotation.json", "[]");
  EXPECT_TRUE(read_table<SampleAnnotation>(dir / "sample_annotation.json").empty());
  test::write_text(dir / "attribute.json",
                   "[{\"token\": \"" + test::kMoving + "\", \"name\": \"a\\\"b\\u00e9\", \"description\": \"x\"}]");
  EXPECT_EQ(read_table<Attribute>(dir / "attribute.json")[0].name, "a\"b\xc3\xa9");
}

}  // namespace
}  // namespace nsg::nuscenes

namespace nsg::nuscenes {
namespace {

// Big tables are read in windows (two parsed concurrently); a tiny window size forces that
// path on the fixture: same records, and the same exact errors as the whole-file parse.
class SmallWindows : public ::testing::Test {
 protected:
  void SetUp() override { ::setenv("NSG_JSON_CHUNK_BYTES", "300", 1); }
  void TearDown() override { ::unsetenv("NSG_JSON_CHUNK_BYTES"); }
};

TEST_F(SmallWindows, SameRecordsAsWholeFile) {
  const std::filesystem::path file = test::fixture_root() / "v1.0-mini" / "sample_data.json";
  ASSERT_GT(std::filesystem::file_size(file), 600u);
  const std::vector<SampleData> windowed = read_table<SampleData>(file);
  ::unsetenv("NSG_JSON_CHUNK_BYTES");
  const std::vector<SampleData> whole = read_table<SampleData>(file);
  ASSERT_EQ(windowed.size(), 5u);
  ASSERT_EQ(whole.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(windowed[i].token, whole[i].token);
    EXPECT_EQ(windowed[i].filename, whole[i].filename);
    EXPECT_EQ(windowed[i].timestamp_us, whole[i].timestamp_us);
    EXPECT_EQ(windowed[i].next_token, whole[i].next_token);
  }
  const Database db = Database::load(test::fixture_root(), test::kFixtureVersion);
  EXPECT_EQ(db.sample_data.size(), 5u);
}

TEST_F(SmallWindows, ErrorsNameTheExactRecord) {
  test::FixtureCopy f;
  f.replace_in_table("sample_data", "\"width\": 1600", "\"width\": \"1600\"");  // record 3
  test::expect_error<ParseError>([&] { read_table<SampleData>(f.table("sample_data")); }, "sample_data.json",
                                 {"record 3", test::kSd4, "\"width\""});
}

TEST_F(SmallWindows, BracesInsideStringsDoNotBreakRecords) {
  test::TempDir dir("windows");
  std::string text = "[";
  for (int i = 0; i < 40; ++i) {
    text += std::string(i ? ",\n" : "") + "{\"token\": \"" + strprintf("%032x", i + 1) +
            "\", \"name\": \"a}, {b\", \"description\": \"}  ,\"}";
  }
  test::write_text(dir / "attribute.json", text + "]");
  const std::vector<Attribute> rows = read_table<Attribute>(dir / "attribute.json");
  ASSERT_EQ(rows.size(), 40u);
  EXPECT_EQ(rows[39].name, "a}, {b");
  EXPECT_EQ(rows[39].description, "}  ,");
  EXPECT_EQ(rows[39].token.str(), strprintf("%032x", 40));
}

}  // namespace
}  // namespace nsg::nuscenes
