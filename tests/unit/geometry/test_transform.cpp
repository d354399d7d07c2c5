#include <gtest/gtest.h>

#include <cmath>

#include <cstring>
#include <vector>

#include "nsg/core/rng.h"
#include "nsg/geometry/transform.h"

namespace nsg::geometry {

constexpr double kPi = 3.14159265358979323846;

TEST(Transform, YawQuaternionRotatesXToY) {
  const Rigid3 t = Rigid3::from_pose({10, 20, 0}, quaternion_from_yaw(kPi / 2));
  const Eigen::Vector3d p = t.apply({1, 0, 0});
  EXPECT_NEAR(p.x(), 10.0, 1e-12);
  EXPECT_NEAR(p.y(), 21.0, 1e-12);
  EXPECT_NEAR(devkit_yaw(quaternion_from_yaw(0.3)), 0.3, 1e-12);
}

TEST(Transform, NonUnitQuaternionIsNormalisedLikePyquaternion) {
  const Quaternion q{2.0, 0.0, 0.0, 0.0};
  EXPECT_TRUE(rotation_matrix(q).isApprox(Eigen::Matrix3d::Identity(), 1e-15));
}

TEST(Transform, InverseAndCompose) {
  const Rigid3 a = Rigid3::from_pose({1, 2, 3}, Quaternion{0.9, 0.1, -0.2, 0.3});
  const Rigid3 b = Rigid3::from_pose({-4, 0.5, 2}, quaternion_from_yaw(1.0));
  const Eigen::Vector3d p(3, -1, 2);
  EXPECT_TRUE((a.inverse().apply(a.apply(p))).isApprox(p, 1e-12));
  EXPECT_TRUE(((a * b).apply(p)).isApprox(a.apply(b.apply(p)), 1e-12));
}

TEST(Transform, DevkitYawHasTheMinusXyTerm) {
  const Quaternion q{0.9, 0.2, 0.1, 0.3};
  const double n = std::sqrt(q.squared_norm());
  const double w = q.w / n, x = q.x / n, y = q.y / n, z = q.z / n;
  EXPECT_DOUBLE_EQ(devkit_yaw(q), std::atan2(2 * (w * z - x * y), 1 - 2 * (y * y + z * z)));
}

TEST(Transform, SensorToEgoToGlobalChainOnFloatPoints) {
  // LIDAR_TOP rotated -90° about z, 1.84 m up; ego at (100, 200) facing north (yaw 90°).
  const Rigid3 ego_from_sensor = Rigid3::from_pose({0.94, 0.0, 1.84}, quaternion_from_yaw(-kPi / 2));
  const Rigid3 global_from_ego = Rigid3::from_pose({100.0, 200.0, 0.0}, quaternion_from_yaw(kPi / 2));
  // A point 10 m ahead of the sensor (+y in the lidar frame) on the ground.
  float pts[5] = {0.0f, 10.0f, -1.84f, 7.0f, 3.0f};
  transform_points_devkit(ego_from_sensor, pts, 1, 5);
  EXPECT_NEAR(pts[0], 10.94, 1e-5);  // forward in ego
  EXPECT_NEAR(pts[1], 0.0, 1e-5);
  EXPECT_NEAR(pts[2], 0.0, 1e-6);
  transform_points_devkit(global_from_ego, pts, 1, 5);
  EXPECT_NEAR(pts[0], 100.0, 1e-4);
  EXPECT_NEAR(pts[1], 210.94, 1e-4);
  EXPECT_EQ(pts[3], 7.0f);  // other columns untouched
  EXPECT_EQ(pts[4], 3.0f);
}

// The vectorized column form must give the same bits as the row form (the devkit's
// float32 arithmetic), including the loop remainder; a sensor → ego → global chain on
// sweep-like points with a real-size translation.
TEST(Transform, ColumnsAreBitIdenticalToRows) {
  Rng rng(5);
  const Rigid3 ego_from_sensor = Rigid3::from_pose({0.985, 0.0, 1.84}, Quaternion{0.7068, -0.0154, 0.0171, -0.7069});
  const Rigid3 global_from_ego = Rigid3::from_pose({411.3, 1180.6, 0.0}, quaternion_from_yaw(2.1));
  for (const size_t n : {size_t{1}, size_t{7}, size_t{1001}}) {
    std::vector<float> rows(5 * n), x(n), y(n), z(n);
    for (size_t i = 0; i < n; ++i) {
      x[i] = rows[5 * i] = static_cast<float>(rng.uniform(-70.0, 70.0));
      y[i] = rows[5 * i + 1] = static_cast<float>(rng.uniform(-70.0, 70.0));
      z[i] = rows[5 * i + 2] = static_cast<float>(rng.uniform(-3.0, 5.0));
    }
    for (const Rigid3* tf : {&ego_from_sensor, &global_from_ego}) {
      transform_points_devkit(*tf, rows.data(), n, 5);
      transform_points_devkit_columns(*tf, x.data(), y.data(), z.data(), n);
    }
    for (size_t i = 0; i < n; ++i) {
      ASSERT_EQ(std::memcmp(&x[i], &rows[5 * i], 4), 0) << "x of point " << i << " of " << n;
      ASSERT_EQ(std::memcmp(&y[i], &rows[5 * i + 1], 4), 0) << "y of point " << i << " of " << n;
      ASSERT_EQ(std::memcmp(&z[i], &rows[5 * i + 2], 4), 0) << "z of point " << i << " of " << n;
    }
  }
}

}  // namespace nsg::geometry
