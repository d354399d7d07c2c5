#pragma once
// An 8-bit gray PNG written row by row (bounded memory for map-sized rasters), atomically,
// with deterministic bytes (fixed zlib level and filter, no time chunk). Internal.
#include <cstdint>
#include <filesystem>
#include <functional>

namespace nsg::synth {

// Calls fill_row(row, buffer) for rows 0..height-1 (row 0 = top) and writes the PNG.
void write_gray_png_rows(const std::filesystem::path& target, int width, int height,
                         const std::function<void(int row, uint8_t* buffer)>& fill_row);

}  // namespace nsg::synth
