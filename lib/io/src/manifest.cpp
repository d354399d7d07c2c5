#include "nsg/io/manifest.h"

#include "nsg/core/error.h"
#include "nsg/io/tile_meta.h"

namespace nsg::io {

namespace {

using nlohmann::json;

std::string text_field(const json& obj, const char* name, const std::string& file, const std::string& at) {
  NSG_CHECK(obj.is_object() && obj.contains(name) && obj[name].is_string(), ParseError, file, at + "/" + name,
            "a string");
  return obj[name].get<std::string>();
}

Region region_from_json(const json& r, const std::string& file, const std::string& at) {
  NSG_CHECK(r.is_object() && r.contains("bounds_m"), ParseError, file, at, "a region {name, split, bounds_m}");
  return {text_field(r, "name", file, at), text_field(r, "split", file, at),
          bounds_from_json(r["bounds_m"], file, at + "/bounds_m")};
}

}  // namespace

std::vector<ManifestLocation> manifest_locations(const json& manifest, const std::string& file) {
  NSG_CHECK(manifest.is_object() && manifest.contains("locations") && manifest["locations"].is_array(), ParseError,
            file, "/locations", "an array of locations");
  std::vector<ManifestLocation> out;
  const json& locations = manifest["locations"];
  for (size_t i = 0; i < locations.size(); ++i) {
    const std::string at = "/locations/" + std::to_string(i);
    ManifestLocation loc;
    loc.name = text_field(locations[i], "name", file, at);
    if (locations[i].contains("regions")) {
      const json& regions = locations[i]["regions"];
      NSG_CHECK(regions.is_array(), ParseError, file, at + "/regions", "an array of regions");
      for (size_t k = 0; k < regions.size(); ++k)
        loc.regions.push_back(region_from_json(regions[k], file, at + "/regions/" + std::to_string(k)));
    }
    out.push_back(std::move(loc));
  }
  return out;
}

nlohmann::ordered_json region_to_json(const Region& r) {
  return {{"name", r.name}, {"split", r.split}, {"bounds_m", r.bounds_m}};
}

}  // namespace nsg::io
