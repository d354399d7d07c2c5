// The leakage figure on positions where it is known by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "nsg/core/files.h"
#include "nsg/frames/config.h"
#include "nsg/frames/leakage.h"
#include "test_support.h"

namespace nsg::frames {
namespace {

TEST(Leakage, ShareWithinTheRadiusAndTheMedianOfTheNearestTrainFrame) {
  const std::vector<EgoPosition> frames = {
      {"a", 0.0, 0.0, 0},   {"a", 100.0, 0.0, 0},  // train
      {"a", 3.0, 4.0, 2},                          // test, 5 m from (0, 0): not within (strictly nearer)
      {"a", 100.0, 2.0, 2},                        // 2 m: within
      {"a", 50.0, 0.0, 2},                         // 50 m
      {"b", 0.0, 0.0, 2},                          // another location, no train frame there
      {"a", 1.0, 0.0, 1},                          // val: neither
  };
  const Leakage l = measure_leakage(frames, 5.0, WindowM{});
  EXPECT_EQ(l.train_frames, 2);
  EXPECT_EQ(l.test_frames, 4);
  EXPECT_EQ(l.test_within_radius, 1);
  ASSERT_TRUE(l.share_within);
  EXPECT_DOUBLE_EQ(*l.share_within, 0.25);
  ASSERT_TRUE(l.median_distance_m);
  EXPECT_DOUBLE_EQ(*l.median_distance_m, 5.0);  // of 2, 5, 50 (location b has no train frame)
}

TEST(Leakage, UndefinedWithoutTestOrTrainFrames) {
  const Leakage none = measure_leakage({}, 5.0, WindowM{});
  EXPECT_FALSE(none.share_within);
  EXPECT_FALSE(none.median_distance_m);
  const Leakage only_test = measure_leakage({{"a", 0.0, 0.0, 2}}, 5.0, WindowM{});
  ASSERT_TRUE(only_test.share_within);
  EXPECT_EQ(*only_test.share_within, 0.0);
  EXPECT_FALSE(only_test.median_distance_m);
}

TEST(Leakage, TheNearestIsExactAmongManyPoints) {
  std::vector<EgoPosition> frames;
  for (int i = 0; i < 200; ++i) frames.push_back({"a", 7.0 * i, (i % 7) * 3.0, 0});
  frames.push_back({"a", 701.0, 9.5, 2});  // nearest train: i = 100 at (700, 6): sqrt(1 + 12.25)
  const Leakage l = measure_leakage(frames, 1.0, WindowM{});
  ASSERT_TRUE(l.median_distance_m);
  double best = 1e9;
  for (int i = 0; i < 200; ++i) best = std::min(best, std::hypot(701.0 - 7.0 * i, 9.5 - (i % 7) * 3.0));
  EXPECT_DOUBLE_EQ(*l.median_distance_m, best);
}

// The radius is the documented 5 m and is applied whole: a test frame 4 m from a train
// frame (inside 5 m, outside half of it) counts; 5.0 m does not (strictly nearer).
TEST(Leakage, TheDocumentedRadiusIsTheDefaultAndIsAppliedWhole) {
  EXPECT_EQ(FramesConfig{}.leak_radius_m, 5.0);
  EXPECT_NE(nsg::read_file(nsg::test::source_dir() / "docs/frames.md").find("`leak_radius_m` (5 m)"),
            std::string::npos);
  const double radius_m = FramesConfig{}.leak_radius_m;
  const Leakage l = measure_leakage({{"a", 0.0, 0.0, 0}, {"a", 0.8 * radius_m, 0.0, 2}, {"a", 0.0, radius_m, 2}},
                                    radius_m, WindowM{});
  EXPECT_EQ(l.test_within_radius, 1);
}

// The window figure where it is known by hand: one train frame at the origin facing +x with
// OpenLane-V2's window (x ±50, y ±25 m: 40 × 20 cells of 2.5 m), and test frames placed so
// that all, a quarter or none of their window lies inside it.
int64_t seen(const std::vector<LeakageBand>& bands) {
  int64_t n = 0;
  for (const LeakageBand& b : bands) n += b.seen_cells;
  return n;
}
int64_t cells(const std::vector<LeakageBand>& bands) {
  int64_t n = 0;
  for (const LeakageBand& b : bands) n += b.window_cells;
  return n;
}

TEST(Leakage, WindowCellsInsideATrainWindowByDistance) {
  const double pi = std::acos(-1.0);
  const EgoPosition train{"a", 0.0, 0.0, 0, 0.0};
  const auto with_test = [&](EgoPosition test) { return window_leakage({train, test}, WindowM{}); };
  const std::vector<LeakageBand> same = with_test({"a", 0.0, 0.0, 2, 0.0});
  ASSERT_EQ(same.size(), 3u);  // the farthest corner is hypot(50, 25) = 55.9 m away
  EXPECT_EQ(same[0].from_m, 0.0);
  EXPECT_EQ(same[2].to_m, 75.0);
  EXPECT_EQ(cells(same), 40 * 20);
  for (const LeakageBand& b : same) EXPECT_EQ(b.seen_cells, b.window_cells) << b.from_m;
  EXPECT_EQ(seen(with_test({"a", 0.0, 0.0, 2, pi})), 800);      // turned round: the same rectangle
  EXPECT_EQ(seen(with_test({"a", 0.0, 0.0, 2, pi / 2})), 400);  // across it: the 50 × 50 m middle
  EXPECT_EQ(seen(with_test({"a", 50.0, 0.0, 2, 0.0})), 400);    // 50 m ahead: the rear half of its window
  EXPECT_EQ(seen(with_test({"a", 100.0, 0.0, 2, 0.0})), 0);     // touching at x = 50 m only
  EXPECT_EQ(seen(with_test({"b", 0.0, 0.0, 2, 0.0})), 0);       // another location
  // The near band is seen before the far one: ahead by 50 m, every seen cell lies behind
  // the test ego (u < 0), so none is farther than hypot(50, 25).
  const std::vector<LeakageBand> ahead = with_test({"a", 50.0, 0.0, 2, 0.0});
  EXPECT_GT(ahead[0].seen_cells, 0);
}

TEST(Leakage, TheLongRangePresetDoublesTheWindowAlongX) {
  const WindowM w = window_of(WindowPreset::kLongRange);
  EXPECT_EQ(w.x_min_m, -100.0);
  EXPECT_EQ(w.x_max_m, 100.0);
  EXPECT_EQ(w.y_min_m, -25.0);
  EXPECT_EQ(w.y_max_m, 25.0);
  // Preset edges unless a source sets one; a set edge wins.
  const FramesConfig c = resolve_frames_config("", {"window.preset=long-range", "window.y_max_m=30"});
  EXPECT_EQ(c.window.x_max_m, 100.0);
  EXPECT_EQ(c.window.y_max_m, 30.0);
  EXPECT_EQ(resolve_frames_config("", {}).window.x_max_m, 50.0);
  // Its bands reach the farthest corner, hypot(100, 25) = 103 m: five of 25 m.
  const std::vector<LeakageBand> bands = window_leakage({{"a", 0.0, 0.0, 0, 0.0}, {"a", 0.0, 0.0, 2, 0.0}}, w);
  EXPECT_EQ(bands.size(), 5u);
  EXPECT_EQ(cells(bands), 80 * 20);
}

}  // namespace
}  // namespace nsg::frames
