#pragma once
// Georeferencing of the four nuScenes map locations (docs/nuscenes-input.md; docs/dataset-format.md).
// Map frame: metres east (x) and north (y) of the location's south-west corner. The
// devkit converts to lat/lon on a sphere of radius 6 378 137 m with the great-circle
// destination from the origin (distance √(x²+y²), bearing atan(x/y)); that is exactly the
// spherical azimuthal-equidistant projection about the origin, which GIS tools know as
// `+proj=aeqd +R=6378137`. GeographicLib stays out of this header.
#include <array>
#include <string>
#include <string_view>

namespace nsg::geometry {

// Radius of the devkit's spherical earth (export_poses.py EARTH_RADIUS_METERS).
inline constexpr double kDevkitEarthRadiusM = 6378137.0;

struct LocationInfo {
  std::string_view name;
  double origin_lat_deg;  // south-west corner of the map
  double origin_lon_deg;
  double canvas_width_m;                  // = canvas_edge[0]
  double canvas_height_m;                 // = canvas_edge[1]
  std::string_view semantic_prior_token;  // stem of maps/<token>.png
};

// The four locations, in the devkit's order (boston-seaport, singapore-onenorth,
// singapore-hollandvillage, singapore-queenstown).
const std::array<LocationInfo, 4>& known_locations();
bool is_known_location(std::string_view name);
// Throws ConfigError naming `name` and the four valid names if it is not one of them.
const LocationInfo& location_info(std::string_view name);

struct LonLat {
  double lon_deg = 0.0;
  double lat_deg = 0.0;
};

// The devkit's conversion (scripts/export_poses.py get_coordinate/derive_latlon),
// expression for expression, for y > 0. The devkit divides by y (ZeroDivisionError at
// y = 0, a mirrored bearing for y < 0); for y ≤ 0 we use atan2(x, y), the geometrically
// correct bearing that continues the same projection.
LonLat map_to_lonlat(std::string_view location, double x_m, double y_m);

// The PROJ definition of the same projection:
// "+proj=aeqd +lat_0=<lat0> +lon_0=<lon0> +R=6378137 +x_0=0 +y_0=0 +units=m"
// (origin printed with shortest round-trip precision).
std::string aeqd_proj_string(std::string_view location);

// Spherical azimuthal-equidistant projection about a location's origin through
// GeographicLib (AzimuthalEquidistant over Geodesic(6378137, 0)). Cheap to copy;
// thread-safe (const methods only).
class AzimuthalProjection {
 public:
  explicit AzimuthalProjection(std::string_view location);
  AzimuthalProjection(double origin_lat_deg, double origin_lon_deg);

  // Map metres → lon/lat (the projection's reverse).
  LonLat to_lonlat(double x_m, double y_m) const;
  // lon/lat → map metres {x, y} (the projection's forward).
  std::array<double, 2> to_map(double lon_deg, double lat_deg) const;

  double origin_lat_deg() const { return lat0_deg_; }
  double origin_lon_deg() const { return lon0_deg_; }

 private:
  double lat0_deg_;
  double lon0_deg_;
};

}  // namespace nsg::geometry
