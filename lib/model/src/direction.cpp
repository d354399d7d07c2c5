#include "nsg/model/direction.h"

#include <cmath>

namespace nsg::model {
namespace {
constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kBinWidthRad = kTwoPi / kDirectionBins;
}  // namespace

double map_angle(double du, double dv) {
  const double a = std::atan2(-dv, du);
  return a < 0.0 ? a + kTwoPi : a;
}

int direction_bin(double angle_rad) {
  double a = std::fmod(angle_rad, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  const int bin = static_cast<int>(a / kBinWidthRad);
  return bin >= kDirectionBins ? kDirectionBins - 1 : bin;  // a rounding to exactly 2π
}

double bin_centre_rad(int bin) { return (bin + 0.5) * kBinWidthRad; }

std::array<double, 2> mean_direction_px(const std::array<float, kDirectionClasses>& votes) {
  std::array<double, 2> m{0.0, 0.0};
  for (int k = 0; k < kDirectionBins; ++k) {
    const double a = bin_centre_rad(k);
    // Map frame (cos, sin) → pixel frame (du, dv) = (cos, −sin).
    m[0] += votes[k] * std::cos(a);
    m[1] -= votes[k] * std::sin(a);
  }
  return m;
}

}  // namespace nsg::model
