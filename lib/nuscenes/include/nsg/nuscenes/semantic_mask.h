#pragma once
// Semantic masks and semantic-prior rasters: 8-bit single-channel PNG (class ids, or 255 =
// foreground for the map prior), read with libpng (reader only).
#include <cstdint>
#include <filesystem>
#include <vector>

namespace nsg::nuscenes {

struct GrayImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // row-major, row 0 at the top
  std::uint8_t at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

// Throws IoError if unreadable, ParseError naming the file if it is not a valid PNG or
// not 8-bit single-channel grayscale (no palette, no alpha, no 16-bit).
GrayImage read_semantic_mask(const std::filesystem::path& file);
// The same into `out`, whose buffer is reused (a reader of many masks keeps one).
void read_semantic_mask(const std::filesystem::path& file, GrayImage& out);

}  // namespace nsg::nuscenes
