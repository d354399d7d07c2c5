#pragma once
// Parameters of the v1 metrics (docs/metrics.md). Defaults are the benchmark's; a report
// records the values it used. Numerical tolerances are part of the definitions, not
// parameters (see the constants in the sources).
#include <nlohmann/json.hpp>

namespace nsg::metrics {

inline constexpr const char* kMetricsVersion = "4";

struct MetricParams {
  double resolution_m = 0.2;      // metres per pixel
  int size_px = 256;              // tile side; pixel masks are size_px x size_px
  double snap_m = 4.0;            // APLS control-point snap radius
  double strict_snap_m = 1.8;     // apls_strict snap radius
  double min_path_m = 0.001;      // APLS pairs with a shorter GT path are skipped
  double direction_match_px = 9;  // direction accuracy: midpoint-to-GT radius
  double lane_width_px = 9;       // F1/IoU capsule diameter
  double geo_step_px = 2;         // GEO/TOPO sampling step
  double geo_match_px = 8;        // GEO/TOPO one-to-one match radius
  double topo_radius_m = 40;      // TOPO path radius

  // Throws ConfigError naming the field when a value is out of range.
  void validate() const;
  nlohmann::json to_json() const;
  // Missing fields keep their defaults; unknown fields and wrong types throw ConfigError.
  static MetricParams from_json(const nlohmann::json& j, const std::string& file = "");
};

}  // namespace nsg::metrics
