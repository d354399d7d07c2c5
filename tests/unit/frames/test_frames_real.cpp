// `nsgraph frames` on the real key frame (tests/data/real/scene-0061-keyframe): the record's
// pose and every camera's calibration equal the devkit's (golden:
// tests/data/golden/real-keyframe/frame-calibration.json, made by make_frame_golden.py
// beside it), and its centerline — of the stand-in map — lies on the map plane through the
// real pose's pitch and roll.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "generate_fixture.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

void expect_matrix_near(const json& got, const json& want, double tol, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (size_t r = 0; r < want.size(); ++r) {
    if (want[r].is_array()) {
      for (size_t c = 0; c < want[r].size(); ++c)
        EXPECT_NEAR(got[r][c].get<double>(), want[r][c].get<double>(), tol) << what << "[" << r << "][" << c << "]";
    } else {
      EXPECT_NEAR(got[r].get<double>(), want[r].get<double>(), tol) << what << "[" << r << "]";
    }
  }
}

TEST(FramesReal, TheRecordCarriesTheDevkitsPoseAndCalibration) {
  TempDir tmp("frames-real");
  const fs::path release = source_dir() / "tests/data/real/scene-0061-keyframe";
  export_real_keyframe_frames(release, tmp.path());
  const json golden = read_json(source_dir() / "tests/data/golden/real-keyframe/frame-calibration.json");
  const json record =
      read_json(tmp / "frames/test/scene-0061/info" / (std::to_string(golden["timestamp"].get<int64_t>()) + ".json"));
  EXPECT_EQ(record["sample_token"], golden["sample_token"]);
  expect_matrix_near(record["pose"]["rotation"], golden["pose"]["rotation"], 1e-12, "pose rotation");
  expect_matrix_near(record["pose"]["translation"], golden["pose"]["translation"], 0.0, "pose translation");
  ASSERT_EQ(record["sensor"].size(), golden["cameras"].size());
  // nuScenes' channel order, as OpenLane-V2 lists its cameras.
  const fs::path record_file =
      tmp / "frames/test/scene-0061/info" / (std::to_string(golden["timestamp"].get<int64_t>()) + ".json");
  const nlohmann::ordered_json in_file_order = nlohmann::ordered_json::parse(read_text(record_file));
  std::vector<std::string> order;
  for (const auto& [channel, cam] : in_file_order["sensor"].items()) order.push_back(channel);
  const std::vector<std::string> want_order = {"CAM_FRONT", "CAM_FRONT_RIGHT", "CAM_FRONT_LEFT",
                                               "CAM_BACK",  "CAM_BACK_LEFT",   "CAM_BACK_RIGHT"};
  EXPECT_EQ(order, want_order);
  for (const auto& [channel, want] : golden["cameras"].items()) {
    SCOPED_TRACE(channel);
    const json& cam = record["sensor"][channel];
    EXPECT_EQ(cam["image_path"], want["filename"]);
    EXPECT_EQ(cam["width"], want["width"]);
    EXPECT_EQ(cam["height"], want["height"]);
    EXPECT_EQ(cam["timestamp"], want["timestamp"]);
    expect_matrix_near(cam["intrinsic"]["K"], want["K"], 0.0, "K");
    expect_matrix_near(cam["extrinsic"]["rotation"], want["extrinsic"]["rotation"], 1e-12, "extrinsic rotation");
    expect_matrix_near(cam["extrinsic"]["translation"], want["extrinsic"]["translation"], 0.0, "extrinsic translation");
    expect_matrix_near(cam["ego_pose"]["rotation"], want["ego_pose"]["rotation"], 1e-12, "ego_pose rotation");
    EXPECT_TRUE(fs::exists(release / cam["image_path"].get<std::string>()));
  }
  // The stand-in map's lane, seen from a pose with pitch and roll: its points are off
  // z = 0 in the ego frame, and on the map plane again through the pose.
  const json& lanes = record["annotation"]["lane_centerline"];
  ASSERT_EQ(lanes.size(), 1u);
  const json& r = record["pose"]["rotation"];
  const json& t = record["pose"]["translation"];
  bool off_plane = false;
  for (const json& p : lanes[0]["points_2m"]) {
    double z = t[2].get<double>();
    for (int k = 0; k < 3; ++k) z += r[2][k].get<double>() * p[k].get<double>();
    EXPECT_NEAR(z, 0.0, 2e-4);
    off_plane = off_plane || std::abs(p[2].get<double>()) > 1e-3;
  }
  EXPECT_TRUE(off_plane);
  // Its lane segment: the stand-in lane lists no dividers, so both lanelines are the
  // centerline moved by half the default lane width, on the map plane too.
  const json& segment = record["annotation"]["lane_segment"].at(0);
  for (const char* side : {"centerline", "left_laneline", "right_laneline"})
    for (const json& p : segment[side]) {
      double z = t[2].get<double>();
      for (int k = 0; k < 3; ++k) z += r[2][k].get<double>() * p[k].get<double>();
      EXPECT_NEAR(z, 0.0, 2e-4) << side;
    }
  EXPECT_EQ(segment["left_laneline_type"], 0);
  const json counts = read_json(tmp / "frames/manifest.json")["counts"];
  EXPECT_EQ(counts["lanelines_from_offset"], 2);
}

}  // namespace
}  // namespace nsg::test
