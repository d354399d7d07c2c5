#pragma once
// The parts of a dataset's manifest.json (docs/dataset-format.md "Manifest") that readers
// other than Dataset need as types: each location's regions. One reader and one writer.
#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::io {

// A region of a location: every tile inside belongs to `split` (docs/dataset-format.md
// "Splits, regions and buffers").
struct Region {
  std::string name, split;
  std::array<double, 4> bounds_m{};  // x_west, y_south, x_east, y_north
};

struct ManifestLocation {
  std::string name;
  std::vector<Region> regions;  // manifest order; empty when the manifest records none
};

// The manifest's `locations` in manifest order. ParseError naming `file` and the JSON path
// (e.g. "/locations/0/regions/2/bounds_m/1") for a missing or mistyped field.
std::vector<ManifestLocation> manifest_locations(const nlohmann::json& manifest, const std::string& file);

// {name, split, bounds_m}: the manifest's record of a region (generate writes it).
nlohmann::ordered_json region_to_json(const Region& region);

}  // namespace nsg::io
