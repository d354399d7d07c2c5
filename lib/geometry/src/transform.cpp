#include "nsg/geometry/transform.h"

#include <cmath>

namespace nsg::geometry {

namespace {
Quaternion normalised(const Quaternion& q) {
  const double n2 = q.squared_norm();
  if (std::abs(1.0 - n2) < 1e-14 || n2 == 0.0) return q;
  const double n = std::sqrt(n2);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}
}  // namespace

Eigen::Matrix3d rotation_matrix(const Quaternion& q_in) {
  const Quaternion q = normalised(q_in);
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  Eigen::Matrix3d r;
  r << w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y), 2 * (x * y + w * z),
      w * w - x * x + y * y - z * z, 2 * (y * z - w * x), 2 * (x * z - w * y), 2 * (y * z + w * x),
      w * w - x * x - y * y + z * z;
  return r;
}

double devkit_yaw(const Quaternion& q_in) {
  const Quaternion q = normalised(q_in);
  return std::atan2(2.0 * (q.w * q.z - q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

Quaternion quaternion_from_yaw(double yaw_rad) { return {std::cos(yaw_rad / 2.0), 0.0, 0.0, std::sin(yaw_rad / 2.0)}; }

Rigid3 Rigid3::from_pose(const std::array<double, 3>& translation, const Quaternion& rotation) {
  Rigid3 t;
  t.rotation = rotation_matrix(rotation);
  t.translation = Eigen::Vector3d(translation[0], translation[1], translation[2]);
  return t;
}

Rigid3 Rigid3::inverse() const {
  Rigid3 t;
  t.rotation = rotation.transpose();
  t.translation = -(t.rotation * translation);
  return t;
}

Rigid3 Rigid3::operator*(const Rigid3& other) const {
  Rigid3 t;
  t.rotation = rotation * other.rotation;
  t.translation = rotation * other.translation + translation;
  return t;
}

void transform_points_devkit(const Rigid3& tf, float* xyz, size_t count, size_t stride_floats) {
  const Eigen::Matrix3d& r = tf.rotation;
  const float tx = static_cast<float>(tf.translation.x());
  const float ty = static_cast<float>(tf.translation.y());
  const float tz = static_cast<float>(tf.translation.z());
  for (size_t i = 0; i < count; ++i) {
    float* p = xyz + i * stride_floats;
    const double x = p[0], y = p[1], z = p[2];
    const float rx = static_cast<float>(r(0, 0) * x + r(0, 1) * y + r(0, 2) * z);
    const float ry = static_cast<float>(r(1, 0) * x + r(1, 1) * y + r(1, 2) * z);
    const float rz = static_cast<float>(r(2, 0) * x + r(2, 1) * y + r(2, 2) * z);
    p[0] = rx + tx;
    p[1] = ry + ty;
    p[2] = rz + tz;
  }
}

namespace {

// Plain loops over restrict-qualified columns so the compiler vectorizes them; the
// expressions keep transform_points_devkit's order of operations.
__attribute__((target_clones("avx2", "default"))) void rotate_translate_columns(const double* r, float tx, float ty,
                                                                                float tz, float* __restrict x,
                                                                                float* __restrict y,
                                                                                float* __restrict z, size_t count) {
  const double r00 = r[0], r01 = r[1], r02 = r[2], r10 = r[3], r11 = r[4], r12 = r[5], r20 = r[6], r21 = r[7],
               r22 = r[8];
  for (size_t i = 0; i < count; ++i) {
    const double px = x[i], py = y[i], pz = z[i];
    const float rx = static_cast<float>(r00 * px + r01 * py + r02 * pz);
    const float ry = static_cast<float>(r10 * px + r11 * py + r12 * pz);
    const float rz = static_cast<float>(r20 * px + r21 * py + r22 * pz);
    x[i] = rx + tx;
    y[i] = ry + ty;
    z[i] = rz + tz;
  }
}

}  // namespace

void transform_points_devkit_columns(const Rigid3& tf, float* x, float* y, float* z, size_t count) {
  const Eigen::Matrix3d& m = tf.rotation;
  const double r[9] = {m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2)};
  rotate_translate_columns(r, static_cast<float>(tf.translation.x()), static_cast<float>(tf.translation.y()),
                           static_cast<float>(tf.translation.z()), x, y, z, count);
}

}  // namespace nsg::geometry
