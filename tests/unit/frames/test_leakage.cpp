// The leakage figure on positions where it is known by hand.
#include <gtest/gtest.h>

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
  const Leakage l = measure_leakage(frames, 5.0);
  EXPECT_EQ(l.train_frames, 2);
  EXPECT_EQ(l.test_frames, 4);
  EXPECT_EQ(l.test_within_radius, 1);
  ASSERT_TRUE(l.share_within);
  EXPECT_DOUBLE_EQ(*l.share_within, 0.25);
  ASSERT_TRUE(l.median_distance_m);
  EXPECT_DOUBLE_EQ(*l.median_distance_m, 5.0);  // of 2, 5, 50 (location b has no train frame)
}

TEST(Leakage, UndefinedWithoutTestOrTrainFrames) {
  const Leakage none = measure_leakage({}, 5.0);
  EXPECT_FALSE(none.share_within);
  EXPECT_FALSE(none.median_distance_m);
  const Leakage only_test = measure_leakage({{"a", 0.0, 0.0, 2}}, 5.0);
  ASSERT_TRUE(only_test.share_within);
  EXPECT_EQ(*only_test.share_within, 0.0);
  EXPECT_FALSE(only_test.median_distance_m);
}

TEST(Leakage, TheNearestIsExactAmongManyPoints) {
  std::vector<EgoPosition> frames;
  for (int i = 0; i < 200; ++i) frames.push_back({"a", 7.0 * i, (i % 7) * 3.0, 0});
  frames.push_back({"a", 701.0, 9.5, 2});  // nearest train: i = 100 at (700, 6): sqrt(1 + 12.25)
  const Leakage l = measure_leakage(frames, 1.0);
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
  const Leakage l =
      measure_leakage({{"a", 0.0, 0.0, 0}, {"a", 0.8 * radius_m, 0.0, 2}, {"a", 0.0, radius_m, 2}}, radius_m);
  EXPECT_EQ(l.test_within_radius, 1);
}

}  // namespace
}  // namespace nsg::frames
