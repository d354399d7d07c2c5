#pragma once
// The classes of the semantic layer (docs/dataset-format.md), declared once: id, name and the
// colour previews, the report and GIS colour tables show. samples/semantic-classes.json is this
// table written out (tests keep them equal); the preview's palette, segment's labels, the
// synthetic cameras, the network's one-hot inputs (C++ and Python, through _nsgraph) and
// stats read it from here.
#include <array>
#include <cstdint>
#include <string_view>

namespace nsg {

struct SemanticClassInfo {
  uint8_t id;                    // the value stored in semantic.tif
  std::string_view name;         // samples/semantic-classes.json's name
  std::array<uint8_t, 3> color;  // sRGB
};

inline constexpr uint8_t kSemanticVoid = 255;  // no class: no data, or a pixel no class fits

inline constexpr std::array<SemanticClassInfo, 14> kSemanticClasses = {{
    {0, "road", {200, 100, 50}},
    {1, "lane_marking", {230, 120, 10}},
    {2, "crosswalk", {250, 250, 120}},
    {3, "sidewalk", {255, 220, 200}},
    {4, "curb", {200, 49, 254}},
    {5, "terrain", {255, 0, 0}},
    {6, "vegetation", {107, 142, 35}},
    {7, "building", {70, 70, 70}},
    {8, "car", {0, 0, 142}},
    {9, "truck_bus", {0, 60, 100}},
    {10, "person", {220, 20, 60}},
    {11, "two_wheeler", {119, 11, 32}},
    {12, "pole_sign", {220, 220, 0}},
    {13, "sky_other", {70, 130, 180}},
}};
inline constexpr int kSemanticClassCount = static_cast<int>(kSemanticClasses.size());

// The table's ids are its positions (readers index it by the stored value).
static_assert([] {
  for (size_t i = 0; i < kSemanticClasses.size(); ++i)
    if (kSemanticClasses[i].id != i) return false;
  return true;
}());

}  // namespace nsg
