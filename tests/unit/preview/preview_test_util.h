#pragma once
// Shared helpers of the preview tests: the e2e dataset's shards and pixel checks.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "generate_fixture.h"
#include "nsg/core/error.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/io.h"
#include "nsg/preview/preview.h"

namespace nsg::test {

inline std::vector<io::DatasetTile> e2e_shard(const std::string& name) {
  const io::Dataset ds = io::Dataset::open(e2e_dataset());
  for (const auto& s : ds.shards())
    if (s.name == name) return ds.read_shard(s);
  ADD_FAILURE() << "no shard " << name;
  return {};
}

inline metrics::Graph tile_graph(const io::DatasetTile& t) { return metrics::tile_graph(t); }

// Pixels of `rect` whose colour is `c`.
inline int count_color(const preview::Image& im, const preview::Rect& rect, preview::Rgb c) {
  int n = 0;
  for (int y = rect.y; y < rect.y + rect.height; ++y)
    for (int x = rect.x; x < rect.x + rect.width; ++x) n += im.at(x, y) == c;
  return n;
}

// The image pixel at the middle of the edge of `graph` whose middle lies farthest from
// every node (so no node dot covers it), in `layer` of `card`. Mirrors draw_graph's
// rounding of the end points.
inline std::pair<int, int> lane_midpoint(const preview::Card& card, const metrics::Graph& g, int layer) {
  auto px = [&](size_t i) {
    return std::array<long, 2>{std::lround((g.nodes[i].u + 0.5) * card.scale - 0.5),
                               std::lround((g.nodes[i].v + 0.5) * card.scale - 0.5)};
  };
  double best = -1;
  std::pair<int, int> out{-1, -1};
  const int size = card.panels[layer].width;
  for (const auto& e : g.edges) {
    const auto a = px(e[0]), b = px(e[1]);
    const double mx = (a[0] + b[0]) / 2.0, my = (a[1] + b[1]) / 2.0;
    if (mx < 3 || my < 3 || mx > size - 4 || my > size - 4) continue;
    double nearest = 1e9;
    for (size_t i = 0; i < g.nodes.size(); ++i) {
      const auto p = px(i);
      nearest = std::min(nearest, std::hypot(p[0] - mx, p[1] - my));
    }
    if (nearest > best) {
      best = nearest;
      out = {card.panels[layer].x + static_cast<int>(std::lround(mx)),
             card.panels[layer].y + static_cast<int>(std::lround(my))};
    }
  }
  EXPECT_GT(best, 5.0) << "an edge midpoint clear of node dots";
  return out;
}

}  // namespace nsg::test
