// camera.semantic_source "auto": the source a release has, decided by what is on disk.
#include <gtest/gtest.h>

#include <filesystem>

#include "nsg/raster/color_layer.h"
#include "test_support.h"

namespace nsg::raster {
namespace {

namespace fs = std::filesystem;

TEST(SemanticSource, AutoTakesMasksThenLidarsegThenNone) {
  test::TempDir root("semantic-source");
  fs::create_directories(root / "v1.0-mini");
  const auto resolved = [&](CameraOptions camera) {
    const std::string chosen = resolve_semantic_source(camera, root.path(), "v1.0-mini");
    return std::make_pair(chosen, camera);
  };
  // Neither: no semantic layer.
  auto [none, none_camera] = resolved(CameraOptions{});
  EXPECT_EQ(none, "none");
  EXPECT_FALSE(none_camera.semantic);
  EXPECT_TRUE(none_camera.rgb);
  // An empty lidarseg table (the test split ships one) is no lidarseg.
  test::write_text(root / "v1.0-mini" / "lidarseg.json", "[]\n");
  EXPECT_EQ(resolved(CameraOptions{}).first, "none");
  // lidarseg.json with records only.
  test::write_text(root / "v1.0-mini" / "lidarseg.json",
                   R"([{"token": "a", "sample_data_token": "b", "filename": "lidarseg/v1.0-mini/b_lidarseg.bin"}])");
  auto [lidarseg, lidarseg_camera] = resolved(CameraOptions{});
  EXPECT_EQ(lidarseg, "lidarseg");
  EXPECT_TRUE(lidarseg_camera.semantic);
  EXPECT_EQ(lidarseg_camera.semantic_source, SemanticSource::kLidarseg);
  // A mask folder wins (the camera segmentation the paper projects), at the default root or
  // at camera.semantic_root.
  fs::create_directories(root / "semantic");
  EXPECT_EQ(resolved(CameraOptions{}).second.semantic_source, SemanticSource::kMasks);
  CameraOptions elsewhere;
  elsewhere.semantic_root = root / "nowhere";
  EXPECT_EQ(resolved(elsewhere).first, "lidarseg");
  // An explicit source, and semantics off, are left alone.
  CameraOptions masks;
  masks.semantic_source = SemanticSource::kMasks;
  masks.semantic_root = root / "nowhere";
  EXPECT_EQ(resolved(masks).first, "");
  EXPECT_EQ(resolved(masks).second.semantic_source, SemanticSource::kMasks);
  CameraOptions off;
  off.semantic = false;
  EXPECT_EQ(resolved(off).first, "");
  EXPECT_EQ(resolved(off).second.semantic_source, SemanticSource::kAuto);
}

}  // namespace
}  // namespace nsg::raster
