#pragma once
// Image encoders for the synthetic release: camera JPEGs like the real nuScenes ones
// (JFIF 1.01, density 1:1, baseline, 4:2:0, libjpeg quality tables) and 8-bit gray PNG
// class masks with deterministic bytes (fixed zlib level and filter, no time chunk).
#include <cstdint>
#include <vector>

#include "nsg/synth/camera_sim.h"

namespace nsg::synth {

// Throws ConfigError on an empty/mis-sized image or quality outside 1..100.
std::vector<uint8_t> encode_jpeg(const CameraImage& image, int quality = 80);
// Throws ConfigError on non-positive size or null data.
std::vector<uint8_t> encode_png_gray8(const uint8_t* data, int width_px, int height_px);
std::vector<uint8_t> encode_png_gray8_from(const CameraImage& image);  // its classes

}  // namespace nsg::synth
