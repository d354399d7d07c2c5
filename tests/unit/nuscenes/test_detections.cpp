// Detection results (docs/nuscenes-input.md): parsing, per-box validation, coverage.
#include <gtest/gtest.h>

#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/detections.h"
#include "nuscenes_fixture.h"

namespace nsg::nuscenes {
namespace {

std::string box(const std::string& sample, const std::string& name = "car", const std::string& score = "0.75",
                const std::string& attribute = "vehicle.moving", const std::string& extra = "") {
  return "{\"sample_token\": \"" + sample + "\", \"translation\": [110.5, 205.25, 1.0], \"size\": [1.9, 4.5, 1.6], " +
         "\"rotation\": [1.0, 0.0, 0.0, 0.0], \"velocity\": [2.5, -0.5], \"detection_name\": \"" + name +
         "\", \"detection_score\": " + score + ", \"attribute_name\": \"" + attribute + "\"" + extra + "}";
}

std::string results(const std::string& body) {
  return "{\"meta\": {\"use_camera\": false, \"use_lidar\": true, \"use_radar\": false, \"use_map\": false, "
         "\"use_external\": false}, \"results\": {" +
         body + "}}";
}

std::string sample_entry(const std::string& sample, const std::string& boxes) {
  return "\"" + sample + "\": [" + boxes + "]";
}

class Detections : public ::testing::Test {
 protected:
  DetectionResults read(const std::string& text) {
    test::write_text(dir_ / "det.json", text);
    return read_detections(dir_ / "det.json");
  }
  void expect_parse_error(const std::string& text, std::initializer_list<std::string> parts) {
    test::write_text(dir_ / "bad.json", text);
    test::expect_error<ParseError>([&] { read_detections(dir_ / "bad.json"); }, "bad.json", parts);
  }
  test::TempDir dir_{"detections"};
};

TEST_F(Detections, ParsesBoxesAndMeta) {
  const DetectionResults r =
      read(results(sample_entry(test::kSample1, box(test::kSample1) + ", " +
                                                    box(test::kSample1, "traffic_cone", "1", "",
                                                        ", \"num_pts\": 4, \"ego_translation\": [1, 2, 3]")) +
                   ", " + sample_entry(test::kSample2, "")));
  EXPECT_TRUE(r.meta.use_lidar);
  EXPECT_FALSE(r.meta.use_camera);
  ASSERT_EQ(r.samples.size(), 2u);
  const DetectionSample& s1 = r.samples[static_cast<size_t>(r.find(Token::from_string(test::kSample1)))];
  ASSERT_EQ(s1.boxes.size(), 2u);
  const DetectionBox& b = s1.boxes[0];
  EXPECT_EQ(b.detection_name, DetectionClass::kCar);
  EXPECT_DOUBLE_EQ(b.detection_score, 0.75);
  EXPECT_EQ(b.attribute_name, "vehicle.moving");
  EXPECT_EQ(b.size[1], 4.5);
  EXPECT_EQ(b.velocity[1], -0.5);
  EXPECT_FALSE(b.num_pts.has_value());
  EXPECT_EQ(s1.boxes[1].detection_name, DetectionClass::kTrafficCone);
  EXPECT_EQ(s1.boxes[1].num_pts, 4);
  EXPECT_EQ((*s1.boxes[1].ego_translation)[2], 3.0);
  EXPECT_TRUE(r.samples[static_cast<size_t>(r.find(Token::from_string(test::kSample2)))].boxes.empty());
}

TEST_F(Detections, BadBoxesNameFileSampleAndBox) {
  const std::string& s = test::kSample1;
  expect_parse_error(results(sample_entry(s, box(s) + ", " + box(s, "car", "1.5"))),
                     {"results[" + s + "]", "box", "record 1", "detection_score", "[0, 1]"});
  expect_parse_error(results(sample_entry(s, box(s, "vehicle.car"))), {s, "detection_name", "vehicle.car"});
  expect_parse_error(results(sample_entry(s, box(s, "pedestrian", "0.5", "vehicle.parked"))),
                     {s, "attribute_name", "pedestrian"});
  expect_parse_error(results(sample_entry(s, box(s, "barrier", "0.5", "vehicle.parked"))), {s, "attribute_name"});
  expect_parse_error(results(sample_entry(s, box(test::kSample2))), {s, "sample_token", test::kSample2});
  expect_parse_error(results(sample_entry(s, box(s, "car", "NaN"))), {s, "detection_score"});
  std::string no_velocity = box(s);
  const std::string velocity_key = "\"velocity\": [2.5, -0.5], ";
  no_velocity.replace(no_velocity.find(velocity_key), velocity_key.size(), "");
  expect_parse_error(results(sample_entry(s, no_velocity)), {s, "velocity", "missing"});
  std::string three_velocity = box(s);
  three_velocity.replace(three_velocity.find("[2.5, -0.5]"), 11, "[2.5, -0.5, 0]");
  expect_parse_error(results(sample_entry(s, three_velocity)), {s, "velocity", "2 finite numbers"});
  expect_parse_error(results(sample_entry(s, box(s).substr(0, 60))), {"truncated or malformed JSON"});
  expect_parse_error("{\"results\": {}}", {"meta", "missing"});
}

TEST_F(Detections, AtMost500BoxesPerSample) {
  const std::string& s = test::kSample1;
  std::string boxes;
  for (int i = 0; i < 500; ++i) boxes += (i ? ", " : "") + box(s);
  EXPECT_EQ(read(results(sample_entry(s, boxes))).samples[0].boxes.size(), 500u);
  expect_parse_error(results(sample_entry(s, boxes + ", " + box(s))), {s, "record 500", "500 boxes"});
}

TEST_F(Detections, DuplicateSampleKey) {
  expect_parse_error(results(sample_entry(test::kSample1, "") + ", " + sample_entry(test::kSample1, "")),
                     {test::kSample1, "once"});
}

TEST_F(Detections, CoverageOfTheDatabaseSamples) {
  const Database db = Database::load(test::fixture_root(), test::kFixtureVersion);
  const DetectionResults both =
      read(results(sample_entry(test::kSample1, box(test::kSample1)) + ", " + sample_entry(test::kSample2, "")));
  EXPECT_NO_THROW(check_covers(both, db));
  const DetectionResults one = read(results(sample_entry(test::kSample1, "")));
  test::expect_error<DataError>([&] { check_covers(one, db); }, "det.json", {test::kSample2, "missing"});
  const Index s1 = db.sample.find(Token::from_string(test::kSample1));
  EXPECT_NO_THROW(check_covers(one, db, std::vector<Index>{s1}));
  test::expect_error<DataError>([&] { check_covers(both, db, std::vector<Index>{s1}); }, "det.json", {test::kSample2});
}

TEST_F(Detections, UnknownSamplesAreRefused) {
  const Database db = Database::load(test::fixture_root(), test::kFixtureVersion);
  // A subset of the release is fine (generate uses what it has) ...
  EXPECT_NO_THROW(check_known_samples(read(results(sample_entry(test::kSample1, ""))), db));
  // ... a sample of another release is not.
  const std::string other(32, 'e');
  const DetectionResults foreign =
      read(results(sample_entry(test::kSample1, "") + ", " + sample_entry(other, box(other))));
  test::expect_error<DataError>([&] { check_known_samples(foreign, db); }, "det.json",
                                {other, "sample token of the release", "sample.json"});
}

TEST(DetectionClasses, NamesAndCategoryMapping) {
  EXPECT_EQ(parse_detection_class("construction_vehicle"), DetectionClass::kConstructionVehicle);
  EXPECT_FALSE(parse_detection_class("vehicle.car"));
  EXPECT_STREQ(detection_class_name(DetectionClass::kTrafficCone), "traffic_cone");
  EXPECT_EQ(detection_class_of_category("vehicle.bus.bendy"), DetectionClass::kBus);
  EXPECT_EQ(detection_class_of_category("human.pedestrian.police_officer"), DetectionClass::kPedestrian);
  EXPECT_FALSE(detection_class_of_category("human.pedestrian.stroller"));
  EXPECT_FALSE(detection_class_of_category("vehicle.emergency.ambulance"));
  EXPECT_TRUE(is_vehicle_class(DetectionClass::kTrailer));
  EXPECT_FALSE(is_vehicle_class(DetectionClass::kMotorcycle));
  EXPECT_TRUE(attribute_valid_for(DetectionClass::kBicycle, "cycle.with_rider"));
  EXPECT_FALSE(attribute_valid_for(DetectionClass::kBicycle, "vehicle.moving"));
  EXPECT_TRUE(attribute_valid_for(DetectionClass::kBarrier, ""));
}

}  // namespace
}  // namespace nsg::nuscenes
