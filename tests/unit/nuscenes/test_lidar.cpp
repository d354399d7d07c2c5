// LiDAR .pcd.bin reader, the sweep → global chain on analytic cases, and the
// `nsgraph inspect sweep` command on the fixture.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nuscenes_fixture.h"

namespace nsg::nuscenes {
namespace {

using geometry::Quaternion;
using geometry::Rigid3;

void write_floats(const std::filesystem::path& file, const std::vector<float>& values) {
  std::string bytes(values.size() * sizeof(float), '\0');
  if (!values.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());  // data() may be null
  test::write_text(file, bytes);
}

// float32 tolerance of a coordinate near `magnitude` metres: a few ULPs.
double tol(double magnitude) { return 4.0 * std::numeric_limits<float>::epsilon() * std::max(1.0, magnitude); }

TEST(Lidar, ReadsFivePerPoint) {
  test::TempDir dir("lidar");
  write_floats(dir / "a.pcd.bin", {1, 2, 3, 4, 5, -1.5f, 0.25f, 7, 255, 31});
  const std::vector<LidarPoint> points = read_lidar_points(dir / "a.pcd.bin");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0].x, 1.0f);
  EXPECT_EQ(points[0].ring, 5.0f);
  EXPECT_EQ(points[1].y, 0.25f);
  EXPECT_EQ(points[1].intensity, 255.0f);
  write_floats(dir / "empty.pcd.bin", {});
  EXPECT_TRUE(read_lidar_points(dir / "empty.pcd.bin").empty());
}

TEST(Lidar, ReusesBuffer) {
  test::TempDir dir("lidar");
  write_floats(dir / "a.pcd.bin", {1, 2, 3, 4, 5});
  std::vector<LidarPoint> buffer(100);
  read_lidar_points(dir / "a.pcd.bin", buffer);
  EXPECT_EQ(buffer.size(), 1u);
  EXPECT_GE(buffer.capacity(), 100u);
}

TEST(Lidar, SizeNotMultipleOf20IsParseError) {
  test::TempDir dir("lidar");
  test::write_text(dir / "bad.pcd.bin", std::string(21, '\0'));
  test::expect_error<ParseError>([&] { read_lidar_points(dir / "bad.pcd.bin"); }, "bad.pcd.bin", {"21 bytes", "20"});
}

TEST(Lidar, NonFinitePointIsParseError) {
  test::TempDir dir("lidar");
  write_floats(dir / "nan.pcd.bin", {1, 2, 3, 4, 5, 1, std::nanf(""), 3, 4, 5});
  test::expect_error<ParseError>([&] { read_lidar_points(dir / "nan.pcd.bin"); }, "nan.pcd.bin", {"point 1", "finite"});
  write_floats(dir / "inf.pcd.bin", {1, 2, 3, std::numeric_limits<float>::infinity(), 5});
  test::expect_error<ParseError>([&] { read_lidar_points(dir / "inf.pcd.bin"); }, "inf.pcd.bin", {"point 0"});
}

// The sweep loop's reads: runs of rows with their first row's index, the last run short,
// a bad value reported by its index in the whole file (not in its run).
TEST(Lidar, ReadsInRuns) {
  test::TempDir dir("lidar");
  std::vector<float> values;
  for (int i = 0; i < 7; ++i) values.insert(values.end(), {float(i), 2, 3, 4, 5});
  write_floats(dir / "a.pcd.bin", values);
  LidarFile file(dir / "a.pcd.bin");
  EXPECT_EQ(file.rows(), 7u);
  std::vector<LidarPoint> run;
  std::vector<size_t> firsts;
  std::vector<float> xs;
  while (!file.done()) {
    firsts.push_back(file.read(run, 3));
    for (const LidarPoint& p : run) xs.push_back(p.x);
  }
  EXPECT_EQ(firsts, (std::vector<size_t>{0, 3, 6}));
  EXPECT_EQ(run.size(), 1u);
  EXPECT_EQ(xs, (std::vector<float>{0, 1, 2, 3, 4, 5, 6}));

  values[5 * 4 + 2] = std::nanf("");  // point 4: in the second run
  write_floats(dir / "nan.pcd.bin", values);
  LidarFile bad(dir / "nan.pcd.bin");
  EXPECT_EQ(bad.read(run, 3), 0u);
  test::expect_error<ParseError>([&] { bad.read(run, 3); }, "nan.pcd.bin", {"point 4", "finite"});
  test::write_text(dir / "odd.pcd.bin", std::string(41, '\0'));
  test::expect_error<ParseError>([&] { LidarFile odd(dir / "odd.pcd.bin"); }, "odd.pcd.bin", {"41 bytes"});
}

TEST(Lidar, MissingFileIsIoError) {
  test::expect_error<IoError>([&] { read_lidar_points("/nonexistent/x.pcd.bin"); }, "/nonexistent/x.pcd.bin", {});
}

std::vector<LidarPoint> transformed(const Rigid3& tf, std::vector<LidarPoint> points) {
  geometry::transform_points_devkit(tf, reinterpret_cast<float*>(points.data()), points.size(),
                                    kLidarPointStrideFloats);
  return points;
}

TEST(Transform, IdentityKeepsPointsAndOtherColumns) {
  const std::vector<LidarPoint> in{{1.5f, -2.25f, 3.0f, 77.0f, 12.0f}};
  const std::vector<LidarPoint> out = transformed(Rigid3{}, in);
  EXPECT_EQ(out[0].x, 1.5f);
  EXPECT_EQ(out[0].y, -2.25f);
  EXPECT_EQ(out[0].z, 3.0f);
  EXPECT_EQ(out[0].intensity, 77.0f);  // untouched
  EXPECT_EQ(out[0].ring, 12.0f);
}

TEST(Transform, YawNinetyDegrees) {
  const Rigid3 tf = Rigid3::from_pose({0, 0, 0}, geometry::quaternion_from_yaw(M_PI / 2));
  const std::vector<LidarPoint> out = transformed(tf, {{1, 0, 0, 0, 0}, {0, 2, 5, 0, 0}});
  EXPECT_NEAR(out[0].x, 0.0, tol(1));
  EXPECT_NEAR(out[0].y, 1.0, tol(1));
  EXPECT_NEAR(out[1].x, -2.0, tol(2));
  EXPECT_NEAR(out[1].y, 0.0, tol(2));
  EXPECT_NEAR(out[1].z, 5.0, tol(5));
}

TEST(Transform, TranslationAddedInFloat32) {
  const Rigid3 tf = Rigid3::from_pose({1179.4673290964536, -3.5, 0.0}, Quaternion{});
  const std::vector<LidarPoint> out = transformed(tf, {{0.125f, 1, 2, 0, 0}});
  // The devkit casts the translation to float32 and adds in float32 (§4.4).
  EXPECT_EQ(out[0].x, 0.125f + static_cast<float>(1179.4673290964536));
  EXPECT_EQ(out[0].y, -2.5f);
  EXPECT_EQ(out[0].z, 2.0f);
}

TEST(Transform, UnnormalisedQuaternionIsNormalised) {
  const Rigid3 tf = Rigid3::from_pose({0, 0, 0}, Quaternion{2.0, 0.0, 0.0, 2.0});  // 90° yaw × 2√2
  const std::vector<LidarPoint> out = transformed(tf, {{1, 0, 0, 0, 0}});
  EXPECT_NEAR(out[0].x, 0.0, tol(1));
  EXPECT_NEAR(out[0].y, 1.0, tol(1));
}

class SweepOnFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    db_ = std::make_unique<Database>(Database::load(test::fixture_root(), test::kFixtureVersion));
  }
  std::unique_ptr<Database> db_;
};

TEST_F(SweepOnFixture, GlobalFromSensorUsesCalibrationAndOwnPose) {
  const Index sd = db_->sample_data.find(Token::from_string(test::kSd1));
  const Rigid3 tf = global_from_sensor(*db_, sd);
  // Sensor yaw 90° at (1, 0, 2) on an ego at (100, 200) with yaw 90°: (1,0,0) → (99, 201, 2).
  const Eigen::Vector3d p = tf.apply({1, 0, 0});
  EXPECT_NEAR(p.x(), 99.0, 1e-12);
  EXPECT_NEAR(p.y(), 201.0, 1e-12);
  EXPECT_NEAR(p.z(), 2.0, 1e-12);
}

TEST_F(SweepOnFixture, KeyFrameToGlobal) {
  const std::vector<LidarPoint> points = load_sweep_global(*db_, db_->sample_data.find(Token::from_string(test::kSd1)));
  ASSERT_EQ(points.size(), 3u);
  const double expected[3][4] = {{99, 201, 2, 10}, {100, 199, 2, 20}, {100, 201, 5, 30}};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(points[i].x, expected[i][0], tol(201)) << i;
    EXPECT_NEAR(points[i].y, expected[i][1], tol(201)) << i;
    EXPECT_NEAR(points[i].z, expected[i][2], tol(201)) << i;
    EXPECT_EQ(points[i].intensity, expected[i][3]) << i;
  }
}

TEST_F(SweepOnFixture, SweepUsesItsOwnEgoPose) {
  // The non-key sweep has its own pose (identity rotation at (101, 200)), not its sample's.
  const std::vector<LidarPoint> points = load_sweep_global(*db_, db_->sample_data.find(Token::from_string(test::kSd2)));
  ASSERT_EQ(points.size(), 2u);
  EXPECT_NEAR(points[0].x, 102.0, tol(202));
  EXPECT_NEAR(points[0].y, 202.0, tol(202));
  EXPECT_NEAR(points[0].z, 2.0, tol(202));
  EXPECT_NEAR(points[1].x, 102.0, tol(202));
  EXPECT_NEAR(points[1].y, 200.0, tol(202));
}

TEST_F(SweepOnFixture, CameraRecordIsNotALidarSweep) {
  const Index cam = db_->sample_data.find(Token::from_string(test::kSd4));
  test::expect_error<DataError>([&] { load_sweep_global(*db_, cam); }, "sample_data.json", {test::kSd4, "lidar"});
}

TEST(InspectSweep, PrintsGlobalPoints) {
  const test::CommandResult r = test::run_nsgraph({"inspect", "sweep", "--dataroot", test::fixture_root().string(),
                                                   "--version", "v1.0-mini", "--token", test::kSd1});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["token"], test::kSd1);
  EXPECT_EQ(j["count"], 3);
  ASSERT_EQ(j["points"].size(), 3u);
  const double expected[3][4] = {{99, 201, 2, 10}, {100, 199, 2, 20}, {100, 201, 5, 30}};
  for (size_t i = 0; i < 3; ++i) {
    ASSERT_EQ(j["points"][i].size(), 4u);
    for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(j["points"][i][k].get<double>(), expected[i][k], tol(201));
    EXPECT_EQ(j["points"][i][3].get<double>(), expected[i][3]);
  }
}

TEST(InspectSweep, HeadLimitsPoints) {
  const test::CommandResult r = test::run_nsgraph(
      {"inspect", "sweep", "--dataroot", test::fixture_root().string(), "--token", test::kSd1, "--head", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["count"], 1);
  EXPECT_EQ(j["total"], 3);
  ASSERT_EQ(j["points"].size(), 1u);
}

TEST(InspectSweep, FloatsPrintedShortest) {
  const test::CommandResult r =
      test::run_nsgraph({"inspect", "sweep", "--dataroot", test::fixture_root().string(), "--token", test::kSd3});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // (0.5, -1.5, 0.25) → ego (2.5, 0.5, 2.25) → yaw 180° at (102.5, 200.25): (100, 199.75, 2.25).
  EXPECT_NE(r.out.find("[100, 199.75, 2.25, 255]"), std::string::npos) << r.out;
}

TEST(InspectSweep, UnknownTokenExits2) {
  const std::string unknown = "5d0000000000000000000000000000ff";
  const test::CommandResult r =
      test::run_nsgraph({"inspect", "sweep", "--dataroot", test::fixture_root().string(), "--token", unknown});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(unknown), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(InspectSweep, NonLidarTokenExits2) {
  const test::CommandResult r =
      test::run_nsgraph({"inspect", "sweep", "--dataroot", test::fixture_root().string(), "--token", test::kSd4});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(test::kSd4), std::string::npos) << r.err;
}

TEST(InspectSweep, MalformedTokenExits2) {
  const test::CommandResult r =
      test::run_nsgraph({"inspect", "sweep", "--dataroot", test::fixture_root().string(), "--token", "xyz"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("xyz"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nsg::nuscenes
