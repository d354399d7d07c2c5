// `generate` with the two semantic sources of real data, on the e2e release: masks from
// `segment` (camera.semantic_root) and nuScenes-lidarseg (camera.semantic_source).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <map>

#include "nsg/core/error.h"
#include "nsg/io/dataset.h"
#include "nsg/io/raster.h"
#include "segment_fixture.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

// Tile key → the tile's files.
std::map<std::string, std::map<std::string, std::vector<uint8_t>>> tiles_of(const fs::path& root) {
  std::map<std::string, std::map<std::string, std::vector<uint8_t>>> out;
  io::Dataset::open(root).for_each_tile("", [&](const io::DatasetTile& t) {
    out[t.key] = t.files;
    return true;
  });
  return out;
}

struct Agreement {
  size_t both = 0, agree = 0;
  double fraction() const { return both ? static_cast<double>(agree) / static_cast<double>(both) : 0.0; }
};

// Semantic pixels both datasets cover (only classes in `classes` when not empty) and how many agree.
Agreement semantic_agreement(const fs::path& a, const fs::path& b, const std::vector<uint8_t>& classes = {}) {
  const auto ta = tiles_of(a), tb = tiles_of(b);
  Agreement r;
  for (const auto& [key, files] : ta) {
    const auto it = tb.find(key);
    if (it == tb.end()) continue;
    io::DatasetTile x{key, "", files}, y{key, "", it->second};
    const io::Raster sa = x.raster("semantic.tif"), sb = y.raster("semantic.tif");
    for (size_t i = 0; i < sa.data.size(); ++i) {
      if (sa.data[i] == 255 || sb.data[i] == 255) continue;
      if (!classes.empty() && std::find(classes.begin(), classes.end(), sa.data[i]) == classes.end()) continue;
      ++r.both;
      r.agree += sa.data[i] == sb.data[i];
    }
  }
  return r;
}

// Tiles whose `layer` file differs between two datasets of the same tiles.
size_t layer_tiles_differing(const fs::path& a, const fs::path& b, const std::string& layer) {
  const auto ta = tiles_of(a), tb = tiles_of(b);
  size_t differing = 0;
  for (const auto& [key, files] : ta) {
    const auto it = tb.find(key);
    differing += it == tb.end() || files.at(layer) != it->second.at(layer);
  }
  return differing;
}
size_t semantic_tiles_differing(const fs::path& a, const fs::path& b) {
  return layer_tiles_differing(a, b, "semantic.tif");
}

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& extra) {
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

TEST(GenerateSemantics, SegmentMasksAsSemanticRoot) {
  TempDir dir("gen-segment-masks");
  const fs::path masks = segment_masks("e2e", e2e_release());
  const CommandResult r = run_nsgraph(
      with(e2e_generate_args(dir.path()), {"--threads", "2", "--set", "camera.semantic_root=" + masks.string()}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Agreement a = semantic_agreement(e2e_dataset(), dir.path());
  std::printf("generate, segment masks vs release masks: %zu of %zu semantic pixels agree (%.1f %%)\n", a.agree, a.both,
              100.0 * a.fraction());
  EXPECT_GT(a.both, 50000u);
  EXPECT_GE(a.fraction(), 0.90);
  // The setting takes effect: the segment masks are not the release's (the tiny model gets
  // ≈ 7 % of the pixels wrong), so the semantic tiles differ from the reference's, while
  // LiDAR and RGB do not depend on where the masks come from.
  EXPECT_GT(a.both - a.agree, 2000u);
  EXPECT_GT(semantic_tiles_differing(e2e_dataset(), dir.path()), 0u);
  EXPECT_EQ(layer_tiles_differing(e2e_dataset(), dir.path(), "rgb.tif"), 0u);

  // Pointed at the release's own masks, the same setting gives the reference bytes.
  TempDir own("gen-segment-own-masks");
  const CommandResult o =
      run_nsgraph(with(e2e_generate_args(own.path()),
                       {"--threads", "2", "--set", "camera.semantic_root=" + (e2e_release() / "semantic").string()}));
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_EQ(semantic_tiles_differing(e2e_dataset(), own.path()), 0u);
}

TEST(GenerateSemantics, LidarsegSourceSameBytesAtAnyThreadAndShareCount) {
  TempDir one("gen-lidarseg-one"), shares("gen-lidarseg-shares");
  const std::vector<std::string> set = {"--set", "camera.semantic_source=lidarseg"};
  CommandResult r = run_nsgraph(with(with(e2e_generate_args(one.path()), set), {"--threads", "2"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (int i = 0; i < 2; ++i) {
    r = run_nsgraph(with(with(e2e_generate_args(shares.path()), set),
                         {"--threads", "1", "--shard-index", std::to_string(i), "--num-shards", "2"}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ASSERT_EQ(run_nsgraph({"merge", "--quiet", "--out", shares.path().string()}).exit_code, 0);
  EXPECT_EQ(tree_hashes(one.path()), tree_hashes(shares.path()));

  // LiDAR and RGB as with masks; semantics from the points, agreeing with the masks on the
  // classes both can see (road, sidewalk, terrain, vegetation, building, car).
  const auto masks = tiles_of(e2e_dataset()), lidarseg = tiles_of(one.path());
  ASSERT_EQ(masks.size(), lidarseg.size());
  for (const auto& [key, files] : masks) {
    EXPECT_EQ(files.at("lidar.tif"), lidarseg.at(key).at("lidar.tif")) << key;
    EXPECT_EQ(files.at("rgb.tif"), lidarseg.at(key).at("rgb.tif")) << key;
  }
  const Agreement a = semantic_agreement(e2e_dataset(), one.path(), {0, 3, 5, 6, 7, 8});
  std::printf("generate, lidarseg vs release masks: %zu of %zu semantic pixels agree (%.1f %%)\n", a.agree, a.both,
              100.0 * a.fraction());
  EXPECT_GT(a.both, 20000u);
  EXPECT_GE(a.fraction(), 0.90);
  // The source takes effect: the points' classes are not the masks' (lidarseg has no lane
  // markings or crosswalks, and it labels only the cells a key-frame sweep hit).
  const Agreement all_classes = semantic_agreement(e2e_dataset(), one.path());
  EXPECT_GT(all_classes.both - all_classes.agree, 1000u);
  EXPECT_GT(semantic_tiles_differing(e2e_dataset(), one.path()), masks.size() / 2);
}

TEST(GenerateSemantics, LidarsegWithoutLidarsegJsonNamesIt) {
  // A view of the e2e release without lidarseg.json.
  TempDir dir("gen-no-lidarseg");
  const fs::path release = e2e_release(), view = dir / "release";
  fs::create_directories(view / "v1.0-mini");
  for (const auto& e : fs::directory_iterator(release))
    if (e.path().filename() != "v1.0-mini") fs::create_symlink(e.path(), view / e.path().filename());
  for (const auto& e : fs::directory_iterator(release / "v1.0-mini"))
    if (e.path().filename() != "lidarseg.json") fs::create_symlink(e.path(), view / "v1.0-mini" / e.path().filename());
  std::vector<std::string> args = e2e_generate_args(dir / "out");
  args[std::find(args.begin(), args.end(), "--dataroot") - args.begin() + 1] = view.string();
  const CommandResult r = run_nsgraph(with(args, {"--set", "camera.semantic_source=lidarseg"}));
  EXPECT_EQ(r.exit_code, kExitInput);
  EXPECT_NE(r.err.find("lidarseg.json"), std::string::npos) << r.err;
  const CommandResult bad = run_nsgraph(with(args, {"--set", "camera.semantic_source=radar"}));
  EXPECT_EQ(bad.exit_code, kExitInput);
  EXPECT_NE(bad.err.find("camera.semantic_source"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace nsg::test
