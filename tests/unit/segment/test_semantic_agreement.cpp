// The semantic layer from `segment` masks and from nuScenes-lidarseg against the layer from
// the synthetic release's own masks (the renderer's truth), on the e2e release: the tiny
// model follows the renderer's colours, the lidarseg labels its ray caster's hits.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <map>

#include "nsg/nuscenes/database.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/raster/lidarseg_layer.h"
#include "nsg/segment/labels.h"
#include "segment_fixture.h"

namespace nsg::raster {
namespace {

namespace fs = std::filesystem;

class SemanticAgreement : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    release_ = new fs::path(test::e2e_release());
    db_ = new nuscenes::Database(nuscenes::Database::load(*release_, "v1.0-mini"));
    layers_ = new LocationLayers(accumulate_location(*db_, "boston-seaport", RasterOptions{}, 2));
  }
  static void TearDownTestSuite() {
    delete layers_;
    delete db_;
    delete release_;
  }
  // The semantic layer from the masks under `root` ("" = the release's own).
  static ColorLayer mask_layer(const fs::path& root, int threads = 2) {
    CameraOptions o;
    o.rgb = false;
    o.semantic_root = root;
    return colorize_location(*db_, "boston-seaport", layers_->lidar, {}, o, threads);
  }
  static LidarsegLayer lidarseg_layer(int threads) {
    return accumulate_lidarseg(*db_, scenes_at(*db_, "boston-seaport"), LidarOptions{}, "LIDAR_TOP",
                               segment::builtin_lidarseg_labels().table(), threads);
  }

  static inline fs::path* release_ = nullptr;
  static inline nuscenes::Database* db_ = nullptr;
  static inline LocationLayers* layers_ = nullptr;
};

TEST_F(SemanticAgreement, SegmentMasksAgreeWithTheReleaseMasks) {
  const ColorLayer truth = mask_layer("");
  const ColorLayer ours = mask_layer(test::segment_masks("e2e", *release_));
  size_t covered = 0, agree = 0;
  std::map<std::pair<int, int>, size_t> confusions;  // (truth, ours) → cells
  truth.cells().for_each([&](CellIndex c, const ColorCell& t) {
    if (!(t.flags & kCoverageSemantic)) return;
    const ColorCell* o = ours.cells().find(c);
    ASSERT_NE(o, nullptr);
    ASSERT_TRUE(o->flags & kCoverageSemantic);  // same geometry, same views
    ++covered;
    agree += o->semantic == t.semantic;
    if (o->semantic != t.semantic) ++confusions[{t.semantic, o->semantic}];
  });
  const auto name = [](int c) {
    return c == 255 ? std::string("void") : segment::class_names().at(static_cast<size_t>(c));
  };
  for (const auto& [pair, n] : confusions)
    if (n * 200 > covered)
      std::printf("  %s taken for %s: %zu cells\n", name(pair.first).c_str(), name(pair.second).c_str(), n);
  ASSERT_GT(covered, 10000u);
  const double fraction = static_cast<double>(agree) / static_cast<double>(covered);
  std::printf("segment masks vs release masks: %zu of %zu covered cells agree (%.1f %%)\n", agree, covered,
              100.0 * fraction);
  EXPECT_GE(fraction, 0.90);
}

TEST_F(SemanticAgreement, LidarsegAgreesWithTheMaskLayer) {
  const ColorLayer truth = mask_layer("");
  ColorLayer lidarseg;
  overlay_semantics(lidarseg, lidarseg_layer(2), {});
  // The classes both can see; lidarseg has no lane markings, crosswalks or curbs.
  constexpr std::array<uint8_t, 6> kShared = {0, 3, 5, 6, 7, 8};  // road sidewalk terrain vegetation building car
  std::array<size_t, 14> both{}, agree{};
  truth.cells().for_each([&](CellIndex c, const ColorCell& t) {
    if (!(t.flags & kCoverageSemantic) || std::find(kShared.begin(), kShared.end(), t.semantic) == kShared.end())
      return;
    const ColorCell* l = lidarseg.cells().find(c);
    if (l == nullptr || !(l->flags & kCoverageSemantic)) return;
    ++both[t.semantic];
    agree[t.semantic] += l->semantic == t.semantic;
  });
  size_t total = 0, total_agree = 0;
  for (uint8_t cls : kShared) {
    total += both[cls];
    total_agree += agree[cls];
    std::printf("lidarseg vs masks, %s: %zu of %zu\n", segment::class_names()[cls].c_str(), agree[cls], both[cls]);
  }
  ASSERT_GT(total, 10000u);
  const double fraction = static_cast<double>(total_agree) / static_cast<double>(total);
  std::printf("lidarseg vs masks: %zu of %zu cells both cover agree (%.1f %%)\n", total_agree, total, 100.0 * fraction);
  EXPECT_GE(fraction, 0.90);
}

// A finished colour layer holds its covered cells only (packed blocks), whether the cameras
// coloured it or lidarseg labelled it: a dense layer over every tile was 218 MB of the city
// world's 990 MB peak. Bound: the cells with data, and a bitmap and counts per block.
TEST_F(SemanticAgreement, FinishedColourLayersArePacked) {
  constexpr size_t kBlockBookkeepingBytes = 1024;
  const ColorLayer masks = mask_layer("");
  ColorLayer lidarseg;
  overlay_semantics(lidarseg, lidarseg_layer(2), {});
  for (const ColorLayer* layer : std::array<const ColorLayer*, 2>{&masks, &lidarseg}) {
    size_t with_data = 0;
    layer->cells().for_each([&](CellIndex, const ColorCell& c) { with_data += c.has_data(); });
    ASSERT_GT(with_data, 10000u);
    EXPECT_LE(layer->cells().memory_bytes(),
              with_data * sizeof(ColorCell) + layer->cells().block_count() * kBlockBookkeepingBytes);
    EXPECT_LT(with_data, layer->cells().block_count() * SparseGrid<ColorCell>::kCells / 2);  // a sparse layer
  }
}

TEST_F(SemanticAgreement, LidarsegLayerIsTheSameAtAnyThreadCount) {
  const LidarsegLayer one = lidarseg_layer(1), two = lidarseg_layer(2);
  EXPECT_EQ(one.stats.cells, two.stats.cells);
  EXPECT_EQ(one.stats.points_labelled, two.stats.points_labelled);
  EXPECT_EQ(one.stats.sweeps_without_labels, 0u);
  size_t differ = 0;
  one.cells.for_each([&](CellIndex c, const LidarsegCell& a) {
    const LidarsegCell* b = two.cells.find(c);
    differ += b == nullptr || b->cls != a.cls || b->point != a.point || b->sweep != a.sweep;
  });
  EXPECT_EQ(differ, 0u);
  // Every labelled cell is a LiDAR cell: the same filters and transform as the LiDAR layer.
  size_t outside = 0;
  one.cells.for_each([&](CellIndex c, const LidarsegCell& a) {
    if (!a.has_data()) return;
    const LidarCell* l = layers_->lidar.cells().find(c);
    outside += l == nullptr || !l->has_data();
  });
  EXPECT_EQ(outside, 0u);
}

}  // namespace
}  // namespace nsg::raster
