// The devkit's arcline_path_utils, expression for expression (docs/nuscenes-input.md).
// Built with -ffp-contract=off: a fused multiply-add would change the last bits.
// Every arithmetic expression below keeps the operand order and grouping of the Python
// source (including multiplications by 1.0 and 0.0, which matter for signed zeros), so
// the results are bit-identical to the devkit's on IEEE doubles with glibc's libm.
#include "nsg/geometry/arcline.h"

#include <algorithm>
#include <cmath>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg::geometry {
namespace {

constexpr double kPi = 3.141592653589793;  // math.pi

// The devkit's breakpoint "pose" (1.0, 0.0, curvature): the unit-speed twist of a segment.
struct Twist {
  double x;
  double y;
  double theta;
};

// Python's float `%` (floor-mod): the result takes the sign of the divisor.
double python_fmod(double a, double b) {
  double mod = std::fmod(a, b);
  if (mod != 0.0) {
    if ((b < 0) != (mod < 0)) mod += b;
  } else {
    mod = std::copysign(0.0, b);
  }
  return mod;
}

// group_exponential(pose, t).
Twist group_exponential(const Twist& pose, double t) {
  const double theta = pose.theta * t;
  const double ctheta = std::cos(theta);
  const double stheta = std::sin(theta);
  if (std::fabs(pose.theta) < 1e-6) return {pose.x * t, pose.y * t, theta};
  const double new_x = (pose.y * (ctheta - 1.0) + pose.x * stheta) / pose.theta;
  const double new_y = (pose.x * (1.0 - ctheta) + pose.y * stheta) / pose.theta;
  return {new_x, new_y, theta};
}

// compose_right(left, pose).
Pose2 compose_right(const Pose2& left, const Twist& pose) {
  const double new_x = std::cos(left.yaw) * pose.x - std::sin(left.yaw) * pose.y + left.x;
  const double new_y = std::sin(left.yaw) * pose.x + std::cos(left.yaw) * pose.y + left.y;
  return {new_x, new_y, wrap_angle_devkit(left.yaw + pose.theta)};
}

// compute_segment_sign: +1 left, −1 right, 0 straight.
std::array<int, 3> segment_signs(ArclineShape shape) {
  using S = ArclineShape;
  const int s0 = (shape == S::kLRL || shape == S::kLSL || shape == S::kLSR) ? 1 : -1;
  const int s1 = shape == S::kRLR ? 1 : (shape == S::kLRL ? -1 : 0);
  const int s2 = (shape == S::kLRL || shape == S::kLSL || shape == S::kRSL) ? 1 : -1;
  return {s0, s1, s2};
}

// get_breakpoint_poses.
std::array<Twist, 3> breakpoint_twists(const ArclinePath& path) {
  return {Twist{1.0, 0.0, path.curvature(0)}, Twist{1.0, 0.0, path.curvature(1)}, Twist{1.0, 0.0, path.curvature(2)}};
}

std::string format_double_or_text(double v) {
  return std::isfinite(v) ? nsg::format_double(v) : (std::isnan(v) ? "NaN" : "inf");
}

// Python's sum(segment_length): starts from the integer 0, i.e. ((0 + s0) + s1) + s2.
double python_sum(const std::array<double, 3>& s) { return ((0.0 + s[0]) + s[1]) + s[2]; }

}  // namespace

bool parse_arcline_shape(std::string_view text, ArclineShape* shape) {
  static constexpr std::pair<std::string_view, ArclineShape> kShapes[] = {
      {"LSL", ArclineShape::kLSL}, {"LSR", ArclineShape::kLSR}, {"RSL", ArclineShape::kRSL},
      {"RSR", ArclineShape::kRSR}, {"LRL", ArclineShape::kLRL}, {"RLR", ArclineShape::kRLR}};
  for (const auto& [name, value] : kShapes) {
    if (name == text) {
      *shape = value;
      return true;
    }
  }
  return false;
}

std::string_view arcline_shape_name(ArclineShape shape) {
  switch (shape) {
    case ArclineShape::kLSL: return "LSL";
    case ArclineShape::kLSR: return "LSR";
    case ArclineShape::kRSL: return "RSL";
    case ArclineShape::kRSR: return "RSR";
    case ArclineShape::kLRL: return "LRL";
    case ArclineShape::kRLR: return "RLR";
  }
  return "?";
}

double ArclinePath::length_m() const { return python_sum(segment_length_m); }

double ArclinePath::curvature(int segment) const {
  // segment_sign[i] / radius with a Python int numerator: 0 / r is +0.0 for r > 0.
  return static_cast<double>(segment_signs(shape)[static_cast<size_t>(segment)]) / radius_m;
}

double wrap_angle_devkit(double angle_rad) {
  // principal_value: (a - (-π)) % (2π) + (-π).
  const double interval_min = -kPi;
  const double two_pi = 2 * kPi;
  return python_fmod(angle_rad - interval_min, two_pi) + interval_min;
}

Pose2 arcline_pose_at(const ArclinePath& path, double distance_m) {
  const double path_length = python_sum(path.segment_length_m);
  // The devkit asserts −1e-6 ≤ step ≤ length and then clamps; we clamp only (as under
  // `python -O`), so a last step that rounds past the length stays on the path.
  double step = std::max(0.0, std::min(distance_m, path_length));
  const std::array<Twist, 3> twists = breakpoint_twists(path);
  Pose2 result = path.start_pose;
  for (size_t i = 0; i < twists.size(); ++i) {
    const double length = path.segment_length_m[i];
    if (step <= length) return compose_right(result, group_exponential(twists[i], step));
    result = compose_right(result, group_exponential(twists[i], length));
    step -= length;
  }
  return result;
}

std::vector<Pose2> discretize_arcline(const ArclinePath& path, double resolution_m) {
  // Far beyond any real lane (a 1 km path at 1 mm): guards the point count, not a devkit rule.
  constexpr double kMaxPoints = 1e7;
  const std::array<double, 3>& s = path.segment_length_m;
  const double path_length = python_sum(s);
  NSG_CHECK(std::isfinite(resolution_m) && resolution_m > 0.0, ConfigError, "", "resolution",
            "expected a finite resolution > 0 m, got " + format_double_or_text(resolution_m));
  NSG_CHECK(std::isfinite(path_length) && path_length / resolution_m < kMaxPoints, DataError, "", "arcline path",
            "expected a finite length below 1e7 resolution steps, got " + format_double_or_text(path_length) + " m");
  // int(max(math.ceil(L / r) + 1.5, 2)) == max(ceil(L / r) + 1, 2).
  const double n_ceil = std::ceil(path_length / resolution_m);
  const long n_points = std::max(static_cast<long>(n_ceil) + 1, 2L);
  const double step_m = path_length / static_cast<double>(n_points - 1);
  const std::array<double, 3> cumulative = {s[0], s[0] + s[1], path_length + step_m};
  const std::array<Twist, 3> twists = breakpoint_twists(path);

  std::vector<Pose2> out;
  out.reserve(static_cast<size_t>(n_points));
  Pose2 anchor = path.start_pose;
  size_t segment = 0;
  double anchor_d = 0.0;
  for (long j = 0; j < n_points; ++j) {
    const double d = static_cast<double>(j) * step_m;
    if (segment < 2 && d > cumulative[segment]) {  // crossed a segment end: re-anchor exactly there
      anchor = arcline_pose_at(path, d);
      anchor_d = d;
      ++segment;
    }
    out.push_back(compose_right(anchor, group_exponential(twists[segment], d - anchor_d)));
  }
  return out;
}

std::vector<Pose2> discretize_lane(const std::vector<ArclinePath>& paths, double resolution_m) {
  std::vector<Pose2> out;
  for (const ArclinePath& path : paths) {
    const std::vector<Pose2> poses = discretize_arcline(path, resolution_m);
    out.insert(out.end(), poses.begin(), poses.end());
  }
  return out;
}

}  // namespace nsg::geometry
