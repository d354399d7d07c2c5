#pragma once
// Arcline (Dubins) paths of the nuScenes map expansion and the devkit's discretization,
// reproduced bit for bit (docs/nuscenes-input.md; arcline.cpp is built with
// -ffp-contract=off and evaluates every expression in the devkit's order).
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace nsg::geometry {

// A planar pose in the map frame: metres, metres, yaw in radians counter-clockwise from +x.
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
  bool operator==(const Pose2&) const = default;
};

// The six Dubins words; L = counter-clockwise arc, R = clockwise arc, S = straight.
enum class ArclineShape { kLSL, kLSR, kRSL, kRSR, kLRL, kRLR };

// Parses "LSR" etc.; returns false for anything else.
bool parse_arcline_shape(std::string_view text, ArclineShape* shape);
std::string_view arcline_shape_name(ArclineShape shape);

struct ArclinePath {
  Pose2 start_pose;
  Pose2 end_pose;  // stored in the map, never read by the devkit's discretization
  ArclineShape shape = ArclineShape::kLSL;
  double radius_m = 0.0;
  std::array<double, 3> segment_length_m{};  // s0, s1, s2

  // (s0 + s1) + s2, the devkit's path length.
  double length_m() const;
  // Signed curvature of segment i (sign_i / radius; 0 for S), as the devkit computes it.
  double curvature(int segment) const;
};

// The devkit's `pose_at_length` (requires d ≥ 1e-6 like the devkit's assert; d is
// clamped to [0, length]).
Pose2 arcline_pose_at(const ArclinePath& path, double distance_m);

// The devkit's `discretize(path, resolution)`: max(ceil(L / r) + 1, 2) poses.
std::vector<Pose2> discretize_arcline(const ArclinePath& path, double resolution_m);

// The devkit's `discretize_lane`: concatenation per path, joint poses repeated.
std::vector<Pose2> discretize_lane(const std::vector<ArclinePath>& paths, double resolution_m);

// Python-style wrap to [−π, π) used by the devkit at every composition.
double wrap_angle_devkit(double angle_rad);

}  // namespace nsg::geometry
