// Georeferencing: the devkit's spherical formula and GeographicLib's azimuthal-equidistant
// projection about each location's origin (docs/nuscenes-input.md).
#include "nsg/geometry/georef.h"

#include <GeographicLib/AzimuthalEquidistant.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <cmath>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg::geometry {
namespace {

constexpr double kPi = 3.141592653589793;  // math.pi

// Origins from the devkit's export_poses.py REFERENCE_COORDINATES; canvas sizes and
// semantic-prior tokens from map_api.py / BitMap.
constexpr std::array<LocationInfo, 4> kLocations = {{
    {"boston-seaport", 42.336849169438615, -71.05785369873047, 2979.5, 2118.1, "36092f0b03a857c6a3403e25b4b7aab3"},
    {"singapore-onenorth", 1.2882100868743724, 103.78475189208984, 1585.6, 2025.0, "53992ee3023e5494b90c316c183be829"},
    {"singapore-hollandvillage", 1.2993652317780957, 103.78217697143555, 2808.3, 2922.9,
     "37819e65e09e5547b8a3ceaefba56bb2"},
    {"singapore-queenstown", 1.2782562240223188, 103.76741409301758, 3228.6, 3687.1,
     "93406b464a165eaba6d9de76ca09f5da"},
}};

// The sphere the devkit assumes; GeographicLib's Geodesic is immutable and thread-safe.
const GeographicLib::Geodesic& devkit_sphere() {
  static const GeographicLib::Geodesic sphere(kDevkitEarthRadiusM, 0.0);
  return sphere;
}

// CPython's math.radians / math.degrees.
double radians(double deg) { return deg * (kPi / 180.0); }
double degrees(double rad) { return rad * (180.0 / kPi); }

}  // namespace

const std::array<LocationInfo, 4>& known_locations() { return kLocations; }

bool is_known_location(std::string_view name) {
  for (const LocationInfo& info : kLocations) {
    if (info.name == name) return true;
  }
  return false;
}

const LocationInfo& location_info(std::string_view name) {
  for (const LocationInfo& info : kLocations) {
    if (info.name == name) return info;
  }
  throw ConfigError("", "location '" + std::string(name) + "'",
                    "expected one of boston-seaport, singapore-onenorth, "
                    "singapore-hollandvillage, singapore-queenstown");
}

LonLat map_to_lonlat(std::string_view location, double x_m, double y_m) {
  const LocationInfo& info = location_info(location);
  // derive_latlon
  const double bearing = y_m > 0.0 ? std::atan(x_m / y_m) : std::atan2(x_m, y_m);
  const double distance = std::sqrt(x_m * x_m + y_m * y_m);
  // get_coordinate
  const double lat = radians(info.origin_lat_deg);
  const double lon = radians(info.origin_lon_deg);
  const double angular_distance = distance / kDevkitEarthRadiusM;
  const double target_lat = std::asin(std::sin(lat) * std::cos(angular_distance) +
                                      std::cos(lat) * std::sin(angular_distance) * std::cos(bearing));
  const double target_lon = lon + std::atan2(std::sin(bearing) * std::sin(angular_distance) * std::cos(lat),
                                             std::cos(angular_distance) - std::sin(lat) * std::sin(target_lat));
  return {degrees(target_lon), degrees(target_lat)};
}

std::string aeqd_proj_string(std::string_view location) {
  const LocationInfo& info = location_info(location);
  return "+proj=aeqd +lat_0=" + format_double(info.origin_lat_deg) + " +lon_0=" + format_double(info.origin_lon_deg) +
         " +R=6378137 +x_0=0 +y_0=0 +units=m";
}

AzimuthalProjection::AzimuthalProjection(std::string_view location)
    : AzimuthalProjection(location_info(location).origin_lat_deg, location_info(location).origin_lon_deg) {}

AzimuthalProjection::AzimuthalProjection(double origin_lat_deg, double origin_lon_deg)
    : lat0_deg_(origin_lat_deg), lon0_deg_(origin_lon_deg) {
  NSG_CHECK(std::isfinite(origin_lat_deg) && std::fabs(origin_lat_deg) <= 90.0 && std::isfinite(origin_lon_deg),
            ConfigError, "", "projection origin", "expected a finite latitude in [-90, 90] and a finite longitude");
}

LonLat AzimuthalProjection::to_lonlat(double x_m, double y_m) const {
  const GeographicLib::AzimuthalEquidistant projection(devkit_sphere());
  LonLat out;
  projection.Reverse(lat0_deg_, lon0_deg_, x_m, y_m, out.lat_deg, out.lon_deg);
  return out;
}

std::array<double, 2> AzimuthalProjection::to_map(double lon_deg, double lat_deg) const {
  const GeographicLib::AzimuthalEquidistant projection(devkit_sphere());
  std::array<double, 2> xy{};
  projection.Forward(lat0_deg_, lon0_deg_, lat_deg, lon_deg, xy[0], xy[1]);
  return xy;
}

}  // namespace nsg::geometry
