#pragma once
// Rigid transforms in the nuScenes conventions: quaternions are [w, x, y, z] (scalar first)
// rotating the child frame into the parent frame; transforms are named
// `target_from_source` and map points expressed in `source` to `target`.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>

namespace nsg::geometry {

struct Quaternion {
  double w = 1.0, x = 0.0, y = 0.0, z = 0.0;
  static Quaternion from_wxyz(const std::array<double, 4>& q) { return {q[0], q[1], q[2], q[3]}; }
  double squared_norm() const { return w * w + x * x + y * y + z * z; }
};

// pyquaternion's rotation_matrix: the quaternion is divided by its norm when
// |1 − ‖q‖²| ≥ 1e-14, then the usual unit-quaternion matrix.
Eigen::Matrix3d rotation_matrix(const Quaternion& q);

// Yaw as the devkit computes it (pyquaternion yaw_pitch_roll[0]):
// atan2(2(wz − xy), 1 − 2(y² + z²)) on the normalised quaternion.
double devkit_yaw(const Quaternion& q);

// Quaternion of a rotation about +z by `yaw_rad` (counter-clockwise from +x).
Quaternion quaternion_from_yaw(double yaw_rad);

// A rigid transform target_from_source: p_target = rotation · p_source + translation.
struct Rigid3 {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  static Rigid3 from_pose(const std::array<double, 3>& translation, const Quaternion& rotation);
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return rotation * p + translation; }
  Rigid3 inverse() const;
  // (this ∘ other): first `other`, then `this`. a_from_c = a_from_b * b_from_c.
  Rigid3 operator*(const Rigid3& other) const;
};

// Applies target_from_source to `count` float32 points stored as rows of `stride_floats`
// floats starting at `xyz` (x, y, z first), the way the devkit does on its float32
// arrays: rotation as a float64 product rounded to float32, then the translation cast to
// float32 and added in float32 arithmetic (docs/nuscenes-input.md).
void transform_points_devkit(const Rigid3& target_from_source, float* xyz, size_t count, size_t stride_floats);

// The same operations on points stored as columns (x[i], y[i], z[i]): bit-identical to
// transform_points_devkit, and vectorized (an AVX2 clone is picked at run time where the
// CPU has it; no FMA in either, so the bits do not depend on the machine).
void transform_points_devkit_columns(const Rigid3& target_from_source, float* x, float* y, float* z, size_t count);

}  // namespace nsg::geometry
