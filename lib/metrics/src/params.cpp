#include "nsg/metrics/params.h"

#include <cmath>
#include <string>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg::metrics {
namespace {
// A value in (0, max]: the documented range (docs/metrics.md "Parameters"). The upper
// bounds keep a tile's work within the scorer's promise whoever sets the value (a tiny
// geo_step_px or a huge lane_width_px multiplies the samples or the mask's pixels).
void require_in(double value, double max, const char* name) {
  NSG_CHECK(std::isfinite(value) && value > 0.0 && value <= max, ConfigError, "", name,
            "a finite value in (0, " + format_double(max) + "], got " + format_double(value));
}
}  // namespace

void MetricParams::validate() const {
  require_in(resolution_m, 10, "resolution_m");
  NSG_CHECK(size_px > 0 && size_px <= 8192, ConfigError, "", "size_px",
            "an integer in [1, 8192], got " + std::to_string(size_px));
  require_in(snap_m, 100, "snap_m");
  require_in(strict_snap_m, 100, "strict_snap_m");
  require_in(min_path_m, 1000, "min_path_m");
  require_in(direction_match_px, 256, "direction_match_px");
  require_in(lane_width_px, 64, "lane_width_px");
  require_in(geo_step_px, 64, "geo_step_px");
  NSG_CHECK(geo_step_px >= 0.25, ConfigError, "", "geo_step_px",
            "a finite value in [0.25, 64], got " + format_double(geo_step_px));
  require_in(geo_match_px, 256, "geo_match_px");
  require_in(topo_radius_m, 1000, "topo_radius_m");
}

nlohmann::json MetricParams::to_json() const {
  return {{"resolution_m", resolution_m},   {"size_px", size_px},         {"snap_m", snap_m},
          {"strict_snap_m", strict_snap_m}, {"min_path_m", min_path_m},   {"direction_match_px", direction_match_px},
          {"lane_width_px", lane_width_px}, {"geo_step_px", geo_step_px}, {"geo_match_px", geo_match_px},
          {"topo_radius_m", topo_radius_m}};
}

MetricParams MetricParams::from_json(const nlohmann::json& j, const std::string& file) {
  NSG_CHECK(j.is_object(), ConfigError, file, "params", "a JSON object");
  MetricParams p;
  for (const auto& [key, value] : j.items()) {
    if (key == "size_px") {
      NSG_CHECK(value.is_number_integer(), ConfigError, file, "params/size_px", "an integer");
      p.size_px = value.get<int>();
      continue;
    }
    double* field = key == "resolution_m"         ? &p.resolution_m
                    : key == "snap_m"             ? &p.snap_m
                    : key == "strict_snap_m"      ? &p.strict_snap_m
                    : key == "min_path_m"         ? &p.min_path_m
                    : key == "direction_match_px" ? &p.direction_match_px
                    : key == "lane_width_px"      ? &p.lane_width_px
                    : key == "geo_step_px"        ? &p.geo_step_px
                    : key == "geo_match_px"       ? &p.geo_match_px
                    : key == "topo_radius_m"      ? &p.topo_radius_m
                                                  : nullptr;
    NSG_CHECK(field != nullptr, ConfigError, file, "params/" + key, "a known metric parameter");
    NSG_CHECK(value.is_number(), ConfigError, file, "params/" + key, "a number");
    *field = value.get<double>();
  }
  p.validate();
  return p;
}

}  // namespace nsg::metrics
