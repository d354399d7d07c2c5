// `nsgraph frames render` on the real key frame: every camera places a point of the frame's
// ego frame where the official devkit's chain places it (golden:
// tests/data/golden/real-keyframe/frame-projection.json, made by make_projection_golden.py
// beside it), the stand-in map's lane is drawn where it projects, a submission beside it, and
// the output folder is ours alone; with a second stand-in map (a lane along the road ahead),
// the lane lands on the road in the real front image where the devkit projects it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/frames/render.h"
#include "nsg/metrics/frames_documents.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class FramesRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new TempDir("frames-render");
    export_real_keyframe_frames(source_dir() / "tests/data/real/scene-0061-keyframe", tmp_->path());
  }
  static void TearDownTestSuite() {
    delete tmp_;
    tmp_ = nullptr;
  }
  static fs::path frames() { return *tmp_ / "frames"; }
  static fs::path record_file() { return frames() / "test/scene-0061/info/1532402927647951.json"; }
  static metrics::FrameRecord record() {
    return metrics::read_frame_record(read_text(record_file()), record_file().string());
  }
  static CommandResult render(const fs::path& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {
        "frames", "render",    "--quiet", "--export", frames().string(), "--frame", "ca9a282c9e77460f8360f564131a8af5",
        "--out",  out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_nsgraph(args);
  }
  static TempDir* tmp_;
};
TempDir* FramesRender::tmp_ = nullptr;

TEST_F(FramesRender, EveryCameraProjectsAsTheDevkit) {
  const json golden = read_json(source_dir() / "tests/data/golden/real-keyframe/frame-projection.json");
  const metrics::FrameRecord r = record();
  EXPECT_EQ(r.sample_token, golden["sample_token"]);
  ASSERT_EQ(r.cameras.size(), golden["cameras"].size());
  int in_front = 0;
  for (const metrics::FrameCamera& camera : r.cameras) {
    SCOPED_TRACE(camera.channel);
    const json& want = golden["cameras"][camera.channel];
    ASSERT_EQ(want.size(), golden["ego_points"].size());
    for (size_t i = 0; i < want.size(); ++i) {
      const std::array<double, 3> p = golden["ego_points"][i].get<std::array<double, 3>>();
      const frames::ImagePoint got = frames::project_to_image(r, camera, p);
      EXPECT_NEAR(got.depth_m, want[i][2].get<double>(), 1e-9) << i;
      if (want[i][2].get<double>() < frames::kRenderNearM) continue;  // behind: pixels meaningless
      ++in_front;
      EXPECT_NEAR(got.u, want[i][0].get<double>(), 1e-6) << i;
      EXPECT_NEAR(got.v, want[i][1].get<double>(), 1e-6) << i;
    }
  }
  EXPECT_GT(in_front, 300);  // every camera sees part of the ring
}

TEST_F(FramesRender, TheLaneIsDrawnWhereItProjectsAndASubmissionBesideIt) {
  TempDir out("frames-render-out");
  const CommandResult c = render(out / "gt");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json done = read_json(out / "gt/render.json");
  EXPECT_EQ(done["ground_truth_centerlines"], 1);
  EXPECT_EQ(done["files"].size(), 8u);  // six cameras, bev.png, render.json
  // The stand-in map's lane crosses under the ego at an angle: ahead-right and behind-left.
  EXPECT_EQ(done["truth_pieces_in_image"]["CAM_FRONT_RIGHT"], 1);
  EXPECT_EQ(done["truth_pieces_in_image"]["CAM_BACK_LEFT"], 1);
  EXPECT_EQ(done["truth_pieces_in_image"]["CAM_FRONT"], 0);
  const metrics::FrameRecord r = record();
  const metrics::FrameCamera* front_right = nullptr;
  for (const auto& cam : r.cameras)
    if (cam.channel == "CAM_FRONT_RIGHT") front_right = &cam;
  ASSERT_NE(front_right, nullptr);
  const cv::Mat image = cv::imread((out / "gt/CAM_FRONT_RIGHT.jpg").string(), cv::IMREAD_COLOR);  // BGR
  ASSERT_EQ(image.cols, 1600);
  ASSERT_EQ(image.rows, 900);
  // The middle of the lane's projected piece is painted green.
  const auto pieces = frames::project_polyline(r, *front_right, r.centerlines[0].points);
  ASSERT_EQ(pieces.size(), 1u);
  int green = 0, tried = 0;
  for (size_t i = 1; i < pieces[0].size(); ++i) {
    const double u = 0.5 * (pieces[0][i - 1].u + pieces[0][i].u), v = 0.5 * (pieces[0][i - 1].v + pieces[0][i].v);
    if (u < 2 || v < 2 || u > 1597 || v > 897) continue;
    ++tried;
    const cv::Vec3b px = image.at<cv::Vec3b>(static_cast<int>(v), static_cast<int>(u));
    green += px[1] > 150 && px[1] > px[2] + 80 && px[1] > px[0] + 80 ? 1 : 0;
  }
  ASSERT_GT(tried, 0);
  EXPECT_EQ(green, tried);

  // Version 2: the lane segment's two lanelines (pale green, no arrowhead) in the BEV panel,
  // 10 px a metre, x forward up, y left left.
  EXPECT_EQ(done["ground_truth_lanelines"], 2);
  const cv::Mat bev = cv::imread((out / "gt/bev.png").string(), cv::IMREAD_COLOR);  // BGR
  ASSERT_EQ(bev.rows, 1000);
  ASSERT_EQ(bev.cols, 500);
  for (const auto* line : {&r.lane_segments.at(0).left_laneline, &r.lane_segments.at(0).right_laneline}) {
    const metrics::Point3& mid = (*line)[line->size() / 2];
    const int col = static_cast<int>(std::lround((25.0 - mid[1]) * 10)),
              row = static_cast<int>(std::lround((50.0 - mid[0]) * 10));
    bool pale = false;
    for (int dr = -2; dr <= 2; ++dr)
      for (int dc = -2; dc <= 2; ++dc) {
        const int y = row + dr, x = col + dc;
        if (y < 0 || x < 0 || y >= bev.rows || x >= bev.cols) continue;
        const cv::Vec3b px = bev.at<cv::Vec3b>(y, x);
        pale = pale || (px[1] > 180 && px[2] > 110 && px[0] > 110);
      }
    EXPECT_TRUE(pale) << "laneline at row " << row << ", col " << col;
  }

  // A submission: the lane moved 1.5 m to the left, keyed by OpenLane-V2's identifier.
  json lane = json::array();
  for (const auto& p : r.centerlines[0].points) lane.push_back({p[0], p[1] + 1.5, p[2]});
  const json results = {{"results",
                         {{"test/scene-0061/1532402927647951",
                           {{"predictions",
                             {{"lane_centerline", {{{"id", 0}, {"points", lane}, {"confidence", 0.8}}}},
                              {"topology_lclc", {{0.0}}}}}}}}}};
  write_text(out / "results.json", results.dump());
  const CommandResult s = render(out / "sub", {"--submission", (out / "results.json").string()});
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_EQ(read_json(out / "sub/render.json")["predicted_centerlines"], 1);
}

TEST_F(FramesRender, TheOutputFolderIsOursAlone) {
  TempDir out("frames-render-own");
  write_text(out / "r/notes.txt", "the user's");
  CommandResult c = render(out / "r");
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_NE(c.err.find("--out"), std::string::npos) << c.err;
  c = render(out / "r", {"--overwrite"});  // a file no render of ours listed: refused, kept
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_NE(c.err.find("notes.txt"), std::string::npos) << c.err;
  EXPECT_TRUE(fs::exists(out / "r/notes.txt"));
  fs::remove(out / "r/notes.txt");
  ASSERT_EQ(render(out / "r").exit_code, 0);
  EXPECT_EQ(render(out / "r").exit_code, 2);  // an earlier render: only with --overwrite
  EXPECT_EQ(render(out / "r", {"--overwrite"}).exit_code, 0);
  c = run_nsgraph({"frames", "render", "--quiet", "--export", frames().string(), "--frame", "no-such-frame", "--out",
                   (out / "x").string()});
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_NE(c.err.find("--frame"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(out / "x/render.json"));
}

// The real key frame with a second stand-in map (tests/data/real/road-ahead, made by make_map.py
// there): one lane along the road the ego drives, from 10 m behind it to 60 m ahead. In the
// real CAM_FRONT image the lane is drawn where the devkit places the same map points
// (golden: tests/data/golden/real-keyframe/road-ahead-projection.json, make_road_ahead_golden.py
// beside it), and those pixels of the unrendered image are road: grey, below the horizon.
TEST(FramesRenderRoadAhead, ALaneAheadLandsOnTheRoadInTheFrontCamera) {
  TempDir tmp("frames-render-road-ahead");
  const fs::path release = tmp / "release";
  fs::copy(source_dir() / "tests/data/real/scene-0061-keyframe", release, fs::copy_options::recursive);
  fs::copy_file(source_dir() / "tests/data/real/road-ahead/singapore-onenorth.json",
                release / "maps/expansion/singapore-onenorth.json", fs::copy_options::overwrite_existing);
  export_real_keyframe_frames(release, tmp.path());
  const CommandResult c = run_nsgraph({"frames", "render", "--quiet", "--export", (tmp / "frames").string(), "--frame",
                                       "ca9a282c9e77460f8360f564131a8af5", "--out", (tmp / "render").string()});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json done = read_json(tmp / "render/render.json");
  EXPECT_EQ(done["ground_truth_centerlines"], 1);
  EXPECT_EQ(done["truth_pieces_in_image"]["CAM_FRONT"], 1);
  EXPECT_EQ(done["truth_pieces_in_image"]["CAM_FRONT_LEFT"], 0);
  EXPECT_EQ(done["truth_pieces_in_image"]["CAM_FRONT_RIGHT"], 0);

  const fs::path record_file = tmp / "frames/test/scene-0061/info/1532402927647951.json";
  const metrics::FrameRecord r = metrics::read_frame_record(read_text(record_file), record_file.string());
  ASSERT_EQ(r.centerlines.size(), 1u);
  const metrics::FrameCamera* front = nullptr;
  for (const auto& cam : r.cameras)
    if (cam.channel == "CAM_FRONT") front = &cam;
  ASSERT_NE(front, nullptr);
  const auto pieces = frames::project_polyline(r, *front, r.centerlines[0].points);
  ASSERT_EQ(pieces.size(), 1u);
  // Distance in pixels from an image point to the drawn piece (straight in the image: the lane
  // is straight on the map plane, and a pinhole camera keeps lines straight).
  const auto distance_px = [&](double u, double v) {
    double best = 1e300;
    for (size_t i = 1; i < pieces[0].size(); ++i) {
      const double ax = pieces[0][i - 1].u, ay = pieces[0][i - 1].v, bx = pieces[0][i].u, by = pieces[0][i].v;
      const double len2 = (bx - ax) * (bx - ax) + (by - ay) * (by - ay);
      const double t = len2 > 0 ? std::clamp(((u - ax) * (bx - ax) + (v - ay) * (by - ay)) / len2, 0.0, 1.0) : 0.0;
      best = std::min(best, std::hypot(u - (ax + t * (bx - ax)), v - (ay + t * (by - ay))));
    }
    return best;
  };

  const json golden = read_json(source_dir() / "tests/data/golden/real-keyframe/road-ahead-projection.json");
  EXPECT_EQ(golden["sample_token"], r.sample_token);
  const json& map_points = golden["map_points"];
  const json& want = golden["cameras"]["CAM_FRONT"];
  ASSERT_EQ(want.size(), map_points.size());
  const cv::Mat drawn = cv::imread((tmp / "render/CAM_FRONT.jpg").string(), cv::IMREAD_COLOR);  // BGR
  const cv::Mat photo = cv::imread((release / front->image_path).string(), cv::IMREAD_COLOR);
  ASSERT_EQ(drawn.cols, 1600);
  ASSERT_EQ(photo.rows, 900);
  // The record's window ends 50 m ahead of the LIDAR_TOP ego; the lane's points up to 45 m
  // ahead (camera depth; the camera sits ~1.7 m ahead of the ego origin) are inside it.
  constexpr double kCheckedDepthM = 45.0;
  int checked = 0, green = 0;
  for (size_t i = 0; i < want.size(); ++i) {
    const double u = want[i][0].get<double>(), v = want[i][1].get<double>(), depth = want[i][2].get<double>();
    if (depth < 2.0 * frames::kRenderNearM || depth > kCheckedDepthM) continue;
    if (u < 2 || v < 2 || u > 1597 || v > 897) continue;
    SCOPED_TRACE("map point " + std::to_string(i));
    ++checked;
    EXPECT_LT(distance_px(u, v), 0.5);  // drawn where the devkit projects it
    EXPECT_GT(v, 500.0);                // below the horizon (row ~490 in this image)
    const cv::Vec3b road = photo.at<cv::Vec3b>(static_cast<int>(v), static_cast<int>(u));
    const int chroma = std::max({road[0], road[1], road[2]}) - std::min({road[0], road[1], road[2]});
    EXPECT_LT(chroma, 30) << "asphalt or its paint: grey";
    const cv::Vec3b px = drawn.at<cv::Vec3b>(static_cast<int>(v), static_cast<int>(u));
    green += px[1] > 150 && px[1] > px[2] + 80 && px[1] > px[0] + 80 ? 1 : 0;
  }
  EXPECT_GT(checked, 35);
  EXPECT_EQ(green, checked);
}

}  // namespace
}  // namespace nsg::test
