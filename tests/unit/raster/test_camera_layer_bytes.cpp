// The camera stage's output pinned, so a faster stage is the same stage: a hash of every
// cell of the camera layer (RGB, class, flags, depth) on the tiny synthetic release and on
// the real key frame, against the values of the stage before it was made faster; and
// masks stored at 1/2 of the image's size, read as the full-size mask they stand for.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "nsg/synth/image_encode.h"
#include "release_fixture.h"

namespace nsg::raster {
namespace {

namespace fs = std::filesystem;

// FNV-1a over every cell of the layer in the grid's fixed order (empty cells included).
uint64_t layer_hash(const ColorLayer& layer) {
  uint64_t h = 1469598103934665603ULL;
  const auto mix = [&](const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ULL;
  };
  layer.cells().for_each([&](CellIndex ci, const ColorCell& c) {
    const uint8_t bytes[5] = {c.r, c.g, c.b, c.semantic, c.flags};
    uint32_t depth_bits;
    std::memcpy(&depth_bits, &c.depth_m, sizeof depth_bits);
    mix(&ci.col, sizeof ci.col);
    mix(&ci.row, sizeof ci.row);
    mix(bytes, sizeof bytes);
    mix(&depth_bits, sizeof depth_bits);
  });
  return h;
}

std::string hex(uint64_t h) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(h));
  return s;
}

using CameraLayerBytes = RasterRelease;

TEST_F(CameraLayerBytes, SyntheticReleaseLayerIsUnchanged) {
  CameraOptions rgb_only;
  rgb_only.semantic = false;
  const ColorLayer rgb = colorize_location(*db_, config_->location, layers_->lidar, {}, rgb_only, 1);
  EXPECT_EQ(hex(layer_hash(rgb)), "fecd54ff720112bf") << "RGB only";
  EXPECT_EQ(hex(layer_hash(colors())), "5a4b4ea1d3cf6d3a") << "RGB + semantics";
}

TEST(CameraLayerBytesReal, RealKeyFrameLayerIsUnchanged) {
  const fs::path real = test::data_dir() / "real/scene-0061-keyframe";
  ASSERT_TRUE(fs::exists(real)) << "missing test data " << real;
  const Database db = Database::load(real, "v1.0-mini");
  RasterOptions options;
  const LocationLayers layers = accumulate_location(db, "singapore-onenorth", options, 1);
  CameraOptions camera = options.camera;
  camera.semantic = false;  // the real release has no class masks
  const ColorLayer colors = colorize_location(db, "singapore-onenorth", layers.lidar, {}, camera, 1);
  EXPECT_GT(colors.rgb_cells(), 1000u);
  EXPECT_EQ(hex(layer_hash(colors)), "27b5349283bf08d7");
}

// A mask stored at 1/2 of the image's size gives the layer of the full-size mask whose 2×2
// blocks are that mask's pixels: the class is read from the mask pixel covering the
// nearest full-size pixel. The release's own masks, made blockwise, are the data.
TEST_F(CameraLayerBytes, HalfSizeMasksReadAsTheFullSizeMaskTheyStandFor) {
  const test::TempDir full_root("masks_full"), half_root("masks_half");
  size_t masks = 0;
  for (const auto& channel : fs::directory_iterator(release_ / "semantic")) {
    for (const auto& file : fs::directory_iterator(channel.path())) {
      const nuscenes::GrayImage m = nuscenes::read_semantic_mask(file.path());
      const int hw = (m.width + 1) / 2, hh = (m.height + 1) / 2;
      std::vector<uint8_t> half(static_cast<size_t>(hw) * hh), full(m.pixels.size());
      for (int y = 0; y < hh; ++y)
        for (int x = 0; x < hw; ++x) half[static_cast<size_t>(y) * hw + x] = m.at(2 * x, 2 * y);
      for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x)
          full[static_cast<size_t>(y) * m.width + x] = half[static_cast<size_t>(y / 2) * hw + x / 2];
      const fs::path name = channel.path().filename() / file.path().filename();
      fs::create_directories(full_root.path() / channel.path().filename());
      fs::create_directories(half_root.path() / channel.path().filename());
      const std::vector<uint8_t> full_png = synth::encode_png_gray8(full.data(), m.width, m.height);
      const std::vector<uint8_t> half_png = synth::encode_png_gray8(half.data(), hw, hh);
      write_file_atomic(full_root.path() / name,
                        std::string_view(reinterpret_cast<const char*>(full_png.data()), full_png.size()));
      write_file_atomic(half_root.path() / name,
                        std::string_view(reinterpret_cast<const char*>(half_png.data()), half_png.size()));
      ++masks;
    }
  }
  ASSERT_GT(masks, 0u);
  CameraOptions options;
  options.semantic_root = full_root.path();
  const ColorLayer from_full = colorize_location(*db_, config_->location, layers_->lidar, {}, options, 1);
  options.semantic_root = half_root.path();
  const ColorLayer from_half = colorize_location(*db_, config_->location, layers_->lidar, {}, options, 2);
  EXPECT_GT(from_half.semantic_cells(), 1000u);
  EXPECT_EQ(from_half.semantic_cells(), from_full.semantic_cells());
  EXPECT_EQ(hex(layer_hash(from_half)), hex(layer_hash(from_full)));
}

TEST_F(CameraLayerBytes, MaskOfNoIntegerScaleNamesTheFile) {
  const test::TempDir root("masks_odd");
  fs::path named;
  for (const auto& channel : fs::directory_iterator(release_ / "semantic")) {
    fs::create_directories(root.path() / channel.path().filename());
    for (const auto& file : fs::directory_iterator(channel.path())) {
      const nuscenes::GrayImage m = nuscenes::read_semantic_mask(file.path());
      const int w = m.width / 2 + 3, h = m.height / 2;  // no 1/n of the image's size
      const std::vector<uint8_t> pixels(static_cast<size_t>(w) * h, 1);
      const std::vector<uint8_t> png = synth::encode_png_gray8(pixels.data(), w, h);
      named = root.path() / channel.path().filename() / file.path().filename();
      write_file_atomic(named, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
    }
  }
  CameraOptions options;
  options.semantic_root = root.path();
  try {
    colorize_location(*db_, config_->location, layers_->lidar, {}, options, 1);
    FAIL() << "expected a DataError";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find(root.path().string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1/n"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nsg::raster
