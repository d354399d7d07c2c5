// Frame scoring: OpenLane-V2's evaluator's own numbers (tests/data/golden/frames, made by
// its evaluate() from the mirror) reproduced to 1e-6, the rules on frames where the answer
// is known by hand, and hostile results files refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "nsg/core/files.h"
#include "nsg/metrics/frames.h"
#include "test_support.h"

namespace nsg::metrics {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kGolden = test::source_dir() / "tests/data/golden/frames";

TEST(FramesGolden, EveryResultsFileScoresAsOpenLaneV2sEvaluator) {
  const json expected = json::parse(read_file(kGolden / "expected.json"));
  const FrameSet truth = read_frames_ground_truth_document(kGolden / "gt.json");
  ASSERT_GE(truth.size(), 30u);
  // pred-ties-*: equal confidences and link probabilities, ranked as numpy's argsort ranks
  // them (a stable order gives DET_l 0.2325 for 0.2289 on pred-ties-all.json).
  for (const char* file : {"pred.json", "pred-b.json", "pred-copy.json", "pred-ties-all.json", "pred-ties-half.json",
                           "pred-ties-distinct.json"}) {
    SCOPED_TRACE(file);
    Issues issues;
    const std::optional<FrameSet> pred = read_frames_results(kGolden / file, FrameResultsLimits{}, issues);
    ASSERT_TRUE(pred) << issues.format();
    const FramesReport r = score_frames(truth, *pred);
    const json& want = expected[file];
    EXPECT_EQ(r.frames, want["frames"].get<int64_t>());
    EXPECT_NEAR(r.det_l, want["DET_l"].get<double>(), 1e-6);
    EXPECT_NEAR(r.top_ll, want["TOP_ll"].get<double>(), 1e-6);
    EXPECT_NEAR(r.det_l_per_threshold[0], want["DET_l_per_threshold"]["1.0"].get<double>(), 1e-6);
    EXPECT_NEAR(r.det_l_per_threshold[1], want["DET_l_per_threshold"]["2.0"].get<double>(), 1e-6);
    EXPECT_NEAR(r.det_l_per_threshold[2], want["DET_l_per_threshold"]["3.0"].get<double>(), 1e-6);
    EXPECT_NEAR(r.lane_score, (r.det_l + std::sqrt(r.top_ll)) / 2, 1e-12);
  }
}

// The lane-segment track (tests/data/golden/frames-ls, made by OpenLane-V2's v2.1
// lanesegment evaluate() from the mirror): DET_ls, DET_a, TOP_lsls and its score to 1e-6,
// the ground truth read from the records' lines and resampled as its collect() does.
TEST(FramesGolden, LaneSegmentsAndAreasScoreAsOpenLaneV2sLaneSegmentEvaluator) {
  const fs::path golden = test::source_dir() / "tests/data/golden/frames-ls";
  const json expected = json::parse(read_file(golden / "expected.json"));
  const FrameSet truth = read_frames_ground_truth_document(golden / "gt.json");
  ASSERT_GE(truth.size(), 30u);
  for (const char* file : {"pred.json", "pred-ties.json", "pred-copy.json"}) {
    SCOPED_TRACE(file);
    Issues issues;
    const std::optional<FrameSet> pred = read_frames_results(golden / file, FrameResultsLimits{}, issues);
    ASSERT_TRUE(pred) << issues.format();
    const FramesReport r = score_frames(truth, *pred);
    const json& want = expected[file];
    ASSERT_TRUE(r.has_lane_segments);
    EXPECT_FALSE(r.has_centerlines);  // lane segments only, as LaneSegNet submits
    EXPECT_EQ(r.frames, want["frames"].get<int64_t>());
    EXPECT_NEAR(r.det_ls, want["DET_ls"].get<double>(), 1e-6);
    EXPECT_NEAR(r.det_a, want["DET_a"].get<double>(), 1e-6);
    EXPECT_NEAR(r.top_lsls, want["TOP_lsls"].get<double>(), 1e-6);
    EXPECT_NEAR(r.ls_score, want["score"].get<double>(), 1e-6);
    for (size_t t = 0; t < 3; ++t)
      EXPECT_NEAR(r.det_ls_per_threshold[t], want["DET_ls_per_threshold"][std::to_string(t + 1) + ".0"].get<double>(),
                  1e-6);
    EXPECT_NEAR(r.det_a_per_category[0], want["DET_a_per_category"]["pedestrian_crossing"].get<double>(), 1e-6);
    EXPECT_NEAR(r.det_a_per_category[1], want["DET_a_per_category"]["road_boundary"].get<double>(), 1e-6);
  }
}

// collect()'s _fix_pts_interpolate as shapely places the points: length and walk in x, y,
// z interpolated, a zero-length (x, y) step skipped, float32.
TEST(Frames, LinesAreResampledAsShapelyInterpolates) {
  // Values from shapely 1.8.5: LineString([(0,0,0),(3,4,10),(6,8,0)]).interpolate(2.5) =
  // (1.5, 2, 5); LineString([(0,0,0),(0,0,5),(3,4,0)]) at 0 and 1: (0,0,0), (0.6,0.8,4).
  const std::vector<Point3> a = interpolate_like_collect({{0, 0, 0}, {3, 4, 10}, {6, 8, 0}}, 5);
  ASSERT_EQ(a.size(), 5u);
  EXPECT_EQ(a[1], (Point3{1.5, 2.0, 5.0}));
  EXPECT_EQ(a[3], (Point3{4.5, 6.0, 5.0}));
  EXPECT_EQ(a[4], (Point3{6.0, 8.0, 0.0}));
  const std::vector<Point3> b = interpolate_like_collect({{0, 0, 0}, {0, 0, 5}, {3, 4, 0}}, 6);
  EXPECT_EQ(b[0], (Point3{0, 0, 0}));
  EXPECT_EQ(b[1][2], static_cast<double>(4.0f));
  EXPECT_EQ(b[1][0], static_cast<double>(0.6f));
}

// docs/metrics.md's lane-segment worked example.
TEST(Frames, TheLaneSegmentWorkedExample) {
  const auto line = [](double y, int n, double x0, double x1) {
    std::vector<Point3> out;
    for (int i = 0; i < n; ++i) out.push_back({x0 + (x1 - x0) * i / (n - 1), y, 0.0});
    return out;
  };
  FrameCenterlines gt;
  gt.has_map_elements = true;
  gt.segments = {{line(0, 10, 10, 28), line(1.75, 10, 10, 28), line(-1.75, 10, 10, 28)}};
  gt.topology_lsls = {0};
  gt.areas = {{2, line(-8, 20, -20, 18)}};
  FrameCenterlines pred;
  pred.has_centerlines = false;
  pred.has_map_elements = true;
  pred.segments = {{line(1.2, 10, 10, 28), line(2.95, 10, 10, 28), line(-0.55, 10, 10, 28)}};
  pred.segment_confidence = {0.9};
  pred.topology_lsls = {0};
  pred.areas = {{2, line(-7.3, 20, -20, 18)}};
  pred.area_confidence = {0.8};
  const FramesReport r = score_frames({{"f", gt}}, {{"f", pred}});
  ASSERT_TRUE(r.has_lane_segments);
  EXPECT_EQ(r.det_ls_per_threshold, (std::array<double, 3>{0.0, 1.0, 1.0}));
  EXPECT_NEAR(r.det_ls, 2.0 / 3.0, 1e-7);
  EXPECT_EQ(r.det_a_per_category[0], 1.0);  // no crossing on either side
  EXPECT_NEAR(r.det_a_per_category[1], 2.0 / 3.0, 1e-7);
  EXPECT_NEAR(r.det_a, 5.0 / 6.0, 1e-7);
}

// A frame of straight lanes along x at y = 0, 10, 20 (11 points each), 0 → 1 linked.
FrameCenterlines three_lanes() {
  FrameCenterlines f;
  for (int k = 0; k < 3; ++k) {
    std::vector<Point3> lane;
    for (int i = 0; i <= 10; ++i) lane.push_back({-20.0 + 4.0 * i, 10.0 * k, 0.0});
    f.lanes.push_back(lane);
    f.confidence.push_back(0.9 - 0.1 * k);
  }
  f.topology = {0, 1, 0, 0, 0, 0, 0, 0, 0};
  return f;
}

TEST(Frames, APerfectCopyScoresOneAndNothingScoresZero) {
  const FrameSet truth = {{"a", three_lanes()}};
  const FramesReport copy = score_frames(truth, truth, /*graph_metrics=*/true);
  EXPECT_EQ(copy.det_l, 1.0);
  EXPECT_EQ(copy.top_ll, 1.0);
  EXPECT_EQ(copy.lane_score, 1.0);
  // nsgraph's own metrics on the frame graphs.
  ASSERT_EQ(copy.graph_means.size(), 6u);
  for (const auto& [name, value] : copy.graph_means) {
    ASSERT_TRUE(value) << name;
    EXPECT_EQ(*value, 1.0) << name;
  }
  // Lanes 0 and 1 are 10 m apart: their link is an edge (33 nodes, 30 + 1 edges).
  const Graph g = frame_graph(three_lanes(), true);
  EXPECT_EQ(g.nodes.size(), 33u);
  EXPECT_EQ(g.edges.size(), 31u);
  // A link between ends at one place joins the two centerlines at one node.
  FrameCenterlines joined;
  joined.lanes = {{{0, 0, 0}, {5, 0, 0}, {10, 0, 0}}, {{10, 0, 0}, {10, 5, 0}}};
  joined.confidence = {1, 1};
  joined.topology = {0, 1, 0, 0};
  const Graph j = frame_graph(joined, true);
  EXPECT_EQ(j.nodes.size(), 4u);
  ASSERT_EQ(j.edges.size(), 3u);
  EXPECT_EQ(j.edges[2], (std::array<int64_t, 2>{2, 3}));  // lane 1 leaves lane 0's end node
  const FramesReport none = score_frames(truth, {});
  EXPECT_EQ(none.missing_frames, 1);
  EXPECT_EQ(none.missing_examples, std::vector<std::string>{"a"});
  EXPECT_EQ(none.det_l, 0.0);
  // Unmatched: every true link missed and every other pair a false link (the evaluator's
  // v1.1 rule), so only vertices with neither score (none here: each has a false one).
  EXPECT_EQ(none.top_ll, 0.0);
}

TEST(Frames, AShiftBetweenThresholdsCountsAtTheLargerOnesOnly) {
  // Lane 1 moved 1.5 m sideways: beyond 1 m, within 2 and 3 m. Its relaxation factor is
  // max(0.5, 1 − 0.005 · d) with d its nearest point to the ego: (0, 10) → 0.95, so the
  // relaxed distance is 1.425 m.
  FrameCenterlines pred = three_lanes();
  for (Point3& p : pred.lanes[1]) p[1] += 1.5;
  const FramesReport r = score_frames({{"a", three_lanes()}}, {{"a", pred}});
  // At 1 m: 2 of 3 true positives (ranked 1st and 3rd): precision/recall (1, 1/3), (0.5, 1/3),
  // (2/3, 2/3): interpolated 1 for recall ≤ 1/3, 2/3 up to 2/3, 0 above: (4 · 1 + 3 · 2/3) / 11.
  EXPECT_NEAR(r.det_l_per_threshold[0], (4.0 + 3.0 * 2.0 / 3.0) / 11.0, 1e-6);
  EXPECT_EQ(r.det_l_per_threshold[1], 1.0f);
  EXPECT_EQ(r.det_l_per_threshold[2], 1.0f);
}

fs::path write(const test::TempDir& dir, const std::string& name, const std::string& text) {
  test::write_text(dir / name, text);
  return dir / name;
}

std::string one_frame(const std::string& lanes, const std::string& topology) {
  return R"({"results": {"tok": {"predictions": {"lane_centerline": )" + lanes + R"(, "topology_lclc": )" + topology +
         "}}}}";
}

// A lane segment whose confidence is `confidence` (JSON text).
std::string segment(const std::string& confidence) {
  const std::string line = "[[0, 0, 0], [1, 0, 0]]";
  return R"({"centerline": )" + line + R"(, "left_laneline": )" + line + R"(, "right_laneline": )" + line +
         R"(, "confidence": )" + confidence + "}";
}

// A results file of one frame "tok" with lane segments, their topology and areas only.
std::string segment_frame(const std::string& segments, const std::string& topology, const std::string& areas) {
  return R"({"results": {"tok": {"predictions": {"lane_segment": )" + segments + R"(, "topology_lsls": )" + topology +
         R"(, "area": )" + areas + "}}}}";
}

TEST(FramesResults, HostileFilesAreRefusedByName) {
  test::TempDir dir("frames-results");
  const std::string lane = R"({"id": 0, "points": [[0, 0, 0], [1, 0, 0]], "confidence": 0.5})";
  struct Case {
    std::string name, text, check, pointer;
  };
  const std::vector<Case> cases = {
      {"no-results", R"({"result": {}})", "frames.results.schema", ":"},
      {"no-confidence", one_frame(R"([{"id": 0, "points": [[0, 0, 0], [1, 0, 0]]}])", "[[0]]"), "frames.results.finite",
       "/results/tok/predictions/lane_centerline/0/confidence"},
      {"one-point", one_frame(R"([{"id": 0, "points": [[0, 0, 0]], "confidence": 1}])", "[[0]]"), "frames.results.size",
       "/lane_centerline/0/points"},
      {"2d-point", one_frame(R"([{"id": 0, "points": [[0, 0], [1, 0]], "confidence": 1}])", "[[0]]"),
       "frames.results.schema", "/lane_centerline/0/points/0"},
      {"far", one_frame(R"([{"id": 0, "points": [[0, 0, 0], [1e9, 0, 0]], "confidence": 1}])", "[[0]]"),
       "frames.results.finite", "/lane_centerline/0/points/1"},
      {"topology-shape", one_frame("[" + lane + "]", "[[0, 1]]"), "frames.results.schema",
       "/predictions/topology_lclc/0"},
      {"probability", one_frame("[" + lane + "]", "[[1.5]]"), "frames.results.scores",
       "/predictions/topology_lclc/0/0"},
      {"duplicate-key", R"({"results": {"tok": {}, "tok": {}}})", "submission.json", ""},
      // The lane-segment track's predictions.
      {"segments-object", segment_frame(R"({})", "[]", "[]"), "frames.results.schema", "/predictions/lane_segment"},
      {"segment-no-left", segment_frame(R"([{"centerline": [[0, 0, 0], [1, 0, 0]], "confidence": 1}])", "[[0]]", "[]"),
       "frames.results.schema", "/predictions/lane_segment/0/left_laneline"},
      {"segment-confidence", segment_frame("[" + segment("\"x\"") + "]", "[[0]]", "[]"), "frames.results.finite",
       "/predictions/lane_segment/0/confidence"},
      {"lsls-shape", segment_frame("[" + segment("1") + "]", "[[0, 0]]", "[]"), "frames.results.schema",
       "/predictions/topology_lsls/0"},
      {"area-category",
       segment_frame("[]", "[]", R"([{"category": 3, "points": [[0, 0, 0], [1, 0, 0]], "confidence": 1}])"),
       "frames.results.schema", "/predictions/area/0/category"},
      {"area-point", segment_frame("[]", "[]", R"([{"category": 1, "points": [[0, 0, 0], [1, 0]], "confidence": 1}])"),
       "frames.results.schema", "/predictions/area/0/points/1"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Issues issues;
    EXPECT_FALSE(read_frames_results(write(dir, c.name + ".json", c.text), FrameResultsLimits{}, issues));
    ASSERT_FALSE(issues.empty());
    EXPECT_EQ(issues.items()[0].check, c.check) << issues.format();
    EXPECT_NE(issues.items()[0].subject.find(c.pointer), std::string::npos) << issues.format();
  }
  // Too many centerlines, too many point pairs against the ground truth.
  FrameResultsLimits small;
  small.max_centerlines_per_frame = 1;
  Issues many;
  EXPECT_FALSE(read_frames_results(
      write(dir, "many.json", one_frame("[" + lane + ", " + lane + "]", "[[0, 0], [0, 0]]")), small, many));
  EXPECT_EQ(many.items().at(0).check, "frames.results.size");
  FrameResultsLimits pairs;
  pairs.max_point_pairs_per_frame = 32;  // 33 truth points × 2 predicted points
  Issues work;
  check_frame_work({{"tok", three_lanes()}}, {{"tok", FrameCenterlines{{{{0, 0, 0}, {1, 0, 0}}}, {1.0}, {0.0}}}}, pairs,
                   "r.json", work);
  ASSERT_EQ(work.size(), 1u);
  EXPECT_EQ(work.items()[0].subject, "r.json:/results/tok");
}

// OpenLane-V2 keys results by (split, segment_id, timestamp): such a key finds its frame's
// sample token; a frame named twice (token and identifier) is refused naming both keys.
TEST(FramesResults, IdentifierKeysNameTheirFrameOnce) {
  const std::map<std::string, std::string> ids = {{"test/scene-1/100", "tok-a"}, {"test/scene-1/200", "tok-b"}};
  const FrameCenterlines f = three_lanes();
  FrameSet keyed = {{"test/scene-1/100", f}, {"other", f}, {"tok-b", f}};
  Issues issues;
  key_results_by_token(keyed, ids, "r.json", issues);
  EXPECT_TRUE(issues.empty()) << issues.format();
  ASSERT_EQ(keyed.size(), 3u);
  EXPECT_EQ(keyed[0].first, "tok-a");
  EXPECT_EQ(keyed[1].first, "other");  // neither: an extra frame, counted by score_frames
  EXPECT_EQ(keyed[2].first, "tok-b");
  const FramesReport r = score_frames({{"tok-a", f}, {"tok-b", f}}, keyed);
  EXPECT_EQ(r.det_l, 1.0);
  EXPECT_EQ(r.extra_frames, 1);

  FrameSet twice = {{"tok-a", f}, {"test/scene-1/100", f}};
  Issues dup;
  key_results_by_token(twice, ids, "r.json", dup);
  ASSERT_EQ(dup.size(), 1u) << dup.format();
  EXPECT_EQ(dup.items()[0].check, "frames.results.duplicate");
  EXPECT_EQ(dup.items()[0].subject, "r.json:/results/test~1scene-1~1100");
  EXPECT_NE(dup.items()[0].message.find("\"tok-a\""), std::string::npos) << dup.format();
}

}  // namespace
}  // namespace nsg::metrics
