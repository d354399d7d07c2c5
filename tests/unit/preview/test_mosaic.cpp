// Mosaics of the e2e dataset (128-px tiles): size, legend, captions, the lane graph drawn
// where graph.json puts it, submission overlays, determinism.
#include <gtest/gtest.h>

#include "nsg/core/files.h"
#include "nsg/metrics/params.h"
#include "preview_test_util.h"
#include "test_support.h"

namespace nsg::test {
namespace {

using preview::CardInput;
using preview::Rgb;

std::vector<CardInput> cards_of(const std::vector<io::DatasetTile>& tiles) {
  std::vector<CardInput> cards;
  for (const auto& t : tiles) cards.push_back({&t, false, nullptr, nullptr});
  return cards;
}

TEST(Mosaic, PaletteMatchesSamplesFile) {
  const nlohmann::json doc = read_json(source_dir() / "samples/semantic-classes.json");
  ASSERT_EQ(doc["classes"].size(), static_cast<size_t>(preview::kSemanticClassCount));
  for (const auto& c : doc["classes"]) {
    const int id = c["id"];
    EXPECT_EQ(preview::semantic_name(id), c["name"].get<std::string>());
    EXPECT_EQ(preview::semantic_color(id), (Rgb{c["color"][0], c["color"][1], c["color"][2]})) << id;
  }
  EXPECT_EQ(preview::semantic_color(doc["void_id"]), preview::kNoData);
}

TEST(Mosaic, SizeLegendAndCaptions) {
  const auto tiles = e2e_shard("test-000000");
  ASSERT_EQ(tiles.size(), 4u);
  const preview::Mosaic m = preview::render_mosaic("test-000000", cards_of(tiles), {});
  // 4 cards in one row: margins 12, cards of 2 x 240 px panels + 4 px gap.
  EXPECT_EQ(m.image.width, 2 * 12 + 4 * (2 * 240 + 4) + 3 * 12);
  ASSERT_EQ(m.cards.size(), 4u);
  const preview::Card& last = m.cards.back();
  EXPECT_EQ(m.image.height, last.panels[preview::kVehicle].y + 240 + 12);
  EXPECT_DOUBLE_EQ(last.scale, 240.0 / 128.0);
  // Legend: every swatch holds its colour; graph colours and all classes are listed.
  ASSERT_GE(m.legend.size(), 2u + preview::kSemanticClassCount);
  EXPECT_EQ(m.legend[0].color, preview::kGraphEdge);
  for (const auto& e : m.legend) {
    EXPECT_EQ(m.image.at(e.swatch.x + 6, e.swatch.y + 6), e.color) << e.label;
    EXPECT_LT(e.swatch.y, m.cards[0].caption_rect.y);
  }
  // Captions: key and coverage text, drawn as dark pixels in the caption strip.
  for (size_t i = 0; i < tiles.size(); ++i) {
    const preview::Card& c = m.cards[i];
    EXPECT_EQ(c.key, tiles[i].key);
    ASSERT_EQ(c.caption.size(), 2u);
    EXPECT_EQ(c.caption[0], tiles[i].key);
    EXPECT_NE(c.caption[1].find("coverage L 14.0%"), std::string::npos) << c.caption[1];  // meta: 0.1403
    int dark = 0;
    for (int y = c.caption_rect.y; y < c.caption_rect.y + c.caption_rect.height; ++y)
      for (int x = c.caption_rect.x; x < c.caption_rect.x + 200; ++x) dark += m.image.at(x, y).r < 100;
    EXPECT_GT(dark, 100) << "caption text of " << c.key;
    if (i == 0) break;  // coverage differs per tile; the text check above holds for all
  }
}

TEST(Mosaic, KnownLanePixelInGraphColour) {
  const auto tiles = e2e_shard("test-000000");
  const preview::Mosaic m = preview::render_mosaic("test-000000", cards_of(tiles), {});
  int checked = 0;
  for (size_t i = 0; i < tiles.size(); ++i) {
    const metrics::Graph g = tile_graph(tiles[i]);
    if (g.edges.empty()) continue;
    for (int layer : {preview::kLidar, preview::kSemantic}) {
      const auto [x, y] = lane_midpoint(m.cards[i], g, layer);
      EXPECT_EQ(m.image.at(x, y), preview::kGraphEdge) << tiles[i].key << " layer " << layer << " at " << x << "," << y;
      ++checked;
    }
    // A node is a dot in the node colour.
    const auto p = m.cards[i].to_image(preview::kRgb, g.nodes[0].u, g.nodes[0].v);
    const preview::Rect panel = m.cards[i].panels[preview::kRgb];
    if (panel.contains(static_cast<int>(std::lround(p[0])), static_cast<int>(std::lround(p[1])))) {
      EXPECT_EQ(m.image.at(static_cast<int>(std::lround(p[0])), static_cast<int>(std::lround(p[1]))),
                preview::kGraphNode);
    }
  }
  EXPECT_GE(checked, 2);
}

TEST(Mosaic, SubmissionEqualToGroundTruth) {
  const auto tiles = e2e_shard("test-000000");
  std::vector<metrics::Graph> preds;
  std::vector<metrics::TileMeasurement> scores;
  for (const auto& t : tiles) preds.push_back(tile_graph(t));
  metrics::MetricParams params;
  params.size_px = 128;
  for (size_t i = 0; i < tiles.size(); ++i)
    scores.push_back(metrics::measure(tiles[i].key, preds[i], &preds[i], params));
  std::vector<CardInput> cards;
  for (size_t i = 0; i < tiles.size(); ++i) cards.push_back({&tiles[i], true, &preds[i], &scores[i]});
  cards.push_back({&tiles[0], true, nullptr, nullptr});  // missing prediction
  const preview::Mosaic m = preview::render_mosaic("submission", cards, {});
  EXPECT_EQ(m.legend[0].color, preview::kGtEdge);
  EXPECT_EQ(m.legend[1].color, preview::kPredEdge);
  bool any_edges = false;
  for (size_t i = 0; i < tiles.size(); ++i) {
    const preview::Card& c = m.cards[i];
    ASSERT_EQ(c.caption.size(), 3u);
    if (preds[i].edges.empty()) continue;
    any_edges = true;
    EXPECT_NE(c.caption[2].find("APLS 1.000"), std::string::npos) << c.caption[2];
    EXPECT_NE(c.caption[2].find("F1 1.000"), std::string::npos) << c.caption[2];
    // The prediction (thin, on top) covers the GT's centre line; the GT shows at its rim.
    const auto [x, y] = lane_midpoint(c, preds[i], preview::kLidar);
    EXPECT_EQ(m.image.at(x, y), preview::kPredEdge);
    EXPECT_GT(count_color(m.image, c.panels[preview::kLidar], preview::kGtEdge), 20);
    EXPECT_EQ(count_color(m.image, c.panels[preview::kLidar], preview::kGraphEdge), 0);
  }
  EXPECT_TRUE(any_edges);
  EXPECT_EQ(m.cards.back().caption[2], "prediction missing (scored as empty)");
  EXPECT_EQ(count_color(m.image, m.cards.back().panels[preview::kLidar], preview::kPredEdge), 0);
}

TEST(Mosaic, WorstFirst) {
  auto tile = [](const char* key, std::optional<double> apls, std::optional<double> chamfer) {
    metrics::TileMeasurement t;
    t.key = key;
    t.values[metrics::kApls] = apls;
    t.values[metrics::kChamferMeanM] = chamfer;
    return t;
  };
  const std::vector<metrics::TileMeasurement> in = {tile("a", 0.9, 1.0), tile("b", std::nullopt, std::nullopt),
                                                    tile("c", 0.1, 3.0), tile("d", 0.9, 1.5), tile("e", 0.5, 2.0)};
  auto keys = [](const std::vector<metrics::TileMeasurement>& v) {
    std::string k;
    for (const auto& t : v) k += t.key;
    return k;
  };
  EXPECT_EQ(keys(preview::worst_first(in, "apls")), "ceadb");
  EXPECT_EQ(keys(preview::worst_first(in, "chamfer_mean_m")), "cedab");  // larger distance = worse
  EXPECT_THROW(preview::worst_first(in, "speed"), ConfigError);
}

TEST(Mosaic, DeterministicPng) {
  const auto tiles = e2e_shard("train-000001");
  const auto a = preview::encode_png(preview::render_mosaic("x", cards_of(tiles), {}).image);
  const auto b = preview::encode_png(preview::render_mosaic("x", cards_of(tiles), {}).image);
  ASSERT_GT(a.size(), 1000u);
  EXPECT_EQ(a, b);
  EXPECT_EQ(std::string(a.begin() + 1, a.begin() + 4), "PNG");
}

TEST(Mosaic, SixtyFourCardsAboutFourKWide) {
  const auto tiles = e2e_shard("test-000000");
  std::vector<CardInput> cards;
  for (int i = 0; i < 64; ++i) cards.push_back({&tiles[i % tiles.size()], false, nullptr, nullptr});
  const preview::Mosaic m = preview::render_mosaic("big", cards, {});
  EXPECT_EQ(m.image.width, 2 * 12 + 8 * 484 + 7 * 12);          // 3980
  EXPECT_EQ(m.cards[63].panels[0].y, m.cards[56].panels[0].y);  // 8 rows of 8
}

TEST(Mosaic, MalformedLayerNamesMember) {
  auto tiles = e2e_shard("test-000000");
  tiles[0].files["lidar.tif"] = {1, 2, 3};
  try {
    preview::render_mosaic("bad", cards_of(tiles), {});
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find(tiles[0].key + ".lidar.tif"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nsg::test
