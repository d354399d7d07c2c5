#include "nsg/metrics/params.h"

#include <cmath>
#include <string>

#include "nsg/core/error.h"

namespace nsg::metrics {
namespace {
void require_positive(double value, const char* name) {
  NSG_CHECK(std::isfinite(value) && value > 0.0, ConfigError, "", name,
            "a finite value > 0, got " + std::to_string(value));
}
}  // namespace

void MetricParams::validate() const {
  require_positive(resolution_m, "resolution_m");
  NSG_CHECK(size_px > 0 && size_px <= 8192, ConfigError, "", "size_px",
            "an integer in [1, 8192], got " + std::to_string(size_px));
  require_positive(snap_m, "snap_m");
  require_positive(strict_snap_m, "strict_snap_m");
  require_positive(min_path_m, "min_path_m");
  require_positive(direction_match_px, "direction_match_px");
  require_positive(lane_width_px, "lane_width_px");
  require_positive(geo_step_px, "geo_step_px");
  require_positive(geo_match_px, "geo_match_px");
  require_positive(topo_radius_m, "topo_radius_m");
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
