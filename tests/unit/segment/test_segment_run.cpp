// `nsgraph segment` through the real binary: masks in generate's layout, the same bytes at
// any thread count and share count, resumable, and bad inputs refused with exit 2 naming
// the file. Also runs on the real key frame (tests/data/real/scene-0061-keyframe).
#include <gtest/gtest.h>

#include <fstream>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "nsg/synth/camera_sim.h"
#include "nsg/synth/image_encode.h"
#include "segment_fixture.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

size_t count_files(const fs::path& dir) {
  size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) n += e.is_regular_file();
  return n;
}

TEST(SegmentRun, WritesOneMaskPerKeyFrameImageWhereGenerateReadsIt) {
  const fs::path release = tiny_release();
  const fs::path masks = segment_masks("tiny", release);
  const nuscenes::Database db = nuscenes::Database::load(release, "v1.0-mini");
  size_t images = 0;
  for (const nuscenes::SampleData& sd : db.sample_data) {
    if (sd.modality != nuscenes::Modality::kCamera || !sd.is_key_frame) continue;
    ++images;
    const fs::path mask = masks / db.channel(sd) / (fs::path(sd.filename).stem().string() + ".png");
    const nuscenes::GrayImage m = nuscenes::read_semantic_mask(mask);
    // At the scale generate samples at by default (1/2, sides rounded up).
    EXPECT_EQ(m.width, (sd.width + 1) / 2);
    EXPECT_EQ(m.height, (sd.height + 1) / 2);
  }
  EXPECT_EQ(images, 16u);
  EXPECT_EQ(count_files(masks), images);  // no temp files left behind
}

TEST(SegmentRun, SameBytesAtOneAndTwoThreadsAndAcrossShares) {
  const fs::path release = tiny_release();
  const auto reference = tree_hashes(segment_masks("tiny", release));  // 2 threads, one share
  TempDir one("segment_one_thread");
  ASSERT_EQ(run_nsgraph(segment_args(release, one.path(), {"--threads", "1"})).exit_code, 0);
  EXPECT_EQ(tree_hashes(one.path()), reference);
  TempDir shared("segment_shares");
  for (int i = 0; i < 3; ++i) {
    const CommandResult r = run_nsgraph(segment_args(
        release, shared.path(), {"--threads", "2", "--shard-index", std::to_string(i), "--num-shards", "3"}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  EXPECT_EQ(tree_hashes(shared.path()), reference);
}

TEST(SegmentRun, SlurmArrayVariablesPickTheShare) {
  const fs::path release = tiny_release();
  TempDir dir("segment_slurm");
  ::setenv("SLURM_ARRAY_TASK_ID", "1", 1);
  ::setenv("SLURM_ARRAY_TASK_COUNT", "4", 1);
  const CommandResult r = run_nsgraph(segment_args(release, dir.path(), {"--threads", "1"}));
  ::unsetenv("SLURM_ARRAY_TASK_ID");
  ::unsetenv("SLURM_ARRAY_TASK_COUNT");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_files(dir.path()), 4u);  // items 1, 5, 9, 13 of 16
}

TEST(SegmentRun, ResumesSkippingValidMasksAndRedoingBrokenOnes) {
  const fs::path release = tiny_release();
  TempDir dir("segment_resume");
  ASSERT_EQ(run_nsgraph(segment_args(release, dir.path())).exit_code, 0);
  const auto first = tree_hashes(dir.path());
  // A truncated mask (a run killed mid-write without the atomic rename would leave this).
  const fs::path victim = dir.path() / first.front().first;
  write_text(victim, read_file(victim).substr(0, 100));
  std::vector<std::string> args = segment_args(release, dir.path());
  args.erase(args.begin() + 1);  // not --quiet: the summary line is on stderr
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("1 masks written, 15 already done"), std::string::npos) << r.err;
  EXPECT_EQ(tree_hashes(dir.path()), first);
}

// Exit code 2 and a message naming `name`.
void expect_input_error(const CommandResult& r, const std::string& name) {
  EXPECT_EQ(r.exit_code, kExitInput) << r.err;
  EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
}

TEST(SegmentRun, NotAnOnnxFileNamesIt) {
  TempDir dir("segment_bad_model");
  write_text(dir / "model.onnx", "this is not a protobuf\n");
  std::vector<std::string> args = segment_args(tiny_release(), dir / "out");
  args[std::find(args.begin(), args.end(), "--model") - args.begin() + 1] = (dir / "model.onnx").string();
  expect_input_error(run_nsgraph(args), "model.onnx");
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(SegmentRun, AnOutputThatIsNotNchwNamesTheModel) {
  TempDir dir("segment_flat");
  std::vector<std::string> args = segment_args(tiny_release(), dir / "out");
  args[std::find(args.begin(), args.end(), "--model") - args.begin() + 1] =
      (segment_data() / "flat-output.onnx").string();
  const CommandResult r = run_nsgraph(args);
  expect_input_error(r, "flat-output.onnx");
  EXPECT_NE(r.err.find("N×C×h×w"), std::string::npos) << r.err;
}

TEST(SegmentRun, BadLabelsNameTheFile) {
  TempDir dir("segment_bad_labels");
  const std::string input = R"("input": {"width": 64, "height": 36})";
  write_text(dir / "unknown-class.json",
             R"({"schema_version": "1", )" + input + R"(, "classes": {"0": "road", "1": "tree"}})");
  write_text(dir / "channel-outside.json",
             R"({"schema_version": "1", )" + input + R"(, "classes": {"0": "road", "40": "car"}})");
  write_text(dir / "no-input.json", R"({"schema_version": "1", "classes": {"0": "road"}})");
  for (const char* file : {"unknown-class.json", "channel-outside.json", "no-input.json"}) {
    std::vector<std::string> args = segment_args(tiny_release(), dir / "out");
    args[std::find(args.begin(), args.end(), "--labels") - args.begin() + 1] = (dir / file).string();
    const CommandResult r = run_nsgraph(args);
    expect_input_error(r, file);
    if (std::string(file) == "channel-outside.json") {
      EXPECT_NE(r.err.find("/classes/40"), std::string::npos) << r.err;
    }
  }
}

TEST(SegmentRun, AnImageOfTheWrongSizeNamesIt) {
  // A copy of the tiny release whose first key-frame image is 800×450 instead of 1600×900.
  TempDir dir("segment_small_image");
  const fs::path release = dir / "release";
  fs::copy(tiny_release(), release, fs::copy_options::recursive);
  const nuscenes::Database db = nuscenes::Database::load(release, "v1.0-mini");
  fs::path jpeg;
  for (const nuscenes::SampleData& sd : db.sample_data)
    if (sd.modality == nuscenes::Modality::kCamera && sd.is_key_frame && jpeg.empty()) jpeg = db.file_path(sd);
  synth::CameraImage small;
  small.width_px = 800;
  small.height_px = 450;
  small.rgb.assign(800 * 450 * 3, 90);
  small.classes.assign(800 * 450, 0);
  const std::vector<uint8_t> bytes = synth::encode_jpeg(small);
  write_text(jpeg, std::string(bytes.begin(), bytes.end()));
  const CommandResult r = run_nsgraph(segment_args(release, dir / "out"));
  expect_input_error(r, jpeg.filename().string());
  EXPECT_NE(r.err.find("1600×900"), std::string::npos) << r.err;
}

// A camera channel becomes the masks' folder: a release whose channel is named like a path
// is refused naming sensor.json (exit 2), nothing written outside --out.
TEST(SegmentRun, AChannelNamedLikeAPathIsRefusedByName) {
  TempDir dir("segment_channel_escape");
  const fs::path release = dir / "release";
  fs::copy(tiny_release(), release, fs::copy_options::recursive);
  const fs::path sensor = release / "v1.0-mini" / "sensor.json";
  std::string text = read_file(sensor);
  const size_t at = text.find("\"CAM_FRONT\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 11, "\"../../escaped\"");
  write_text(sensor, text);
  const CommandResult r = run_nsgraph(segment_args(release, dir / "run" / "out"));
  expect_input_error(r, "sensor.json");
  EXPECT_NE(r.err.find("../../escaped"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "escaped"));
  EXPECT_FALSE(fs::exists(dir / "run" / "escaped"));
}

TEST(SegmentRun, RunsOnTheRealKeyFrame) {
  const fs::path real = data_dir() / "real" / "scene-0061-keyframe";
  ASSERT_TRUE(fs::exists(real)) << "missing test data " << real;
  TempDir dir("segment_real");
  const CommandResult r = run_nsgraph(segment_args(real, dir.path(), {"--threads", "2"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nuscenes::Database db = nuscenes::Database::load(real, "v1.0-mini");
  size_t masks = 0;
  for (const nuscenes::SampleData& sd : db.sample_data) {
    if (sd.modality != nuscenes::Modality::kCamera || !sd.is_key_frame) continue;
    const nuscenes::GrayImage m =
        nuscenes::read_semantic_mask(dir.path() / db.channel(sd) / (fs::path(sd.filename).stem().string() + ".png"));
    EXPECT_EQ(m.width, 800);  // 1/2 of 1600 × 900 by default
    EXPECT_EQ(m.height, 450);
    ++masks;
  }
  EXPECT_EQ(masks, 6u);
}

}  // namespace
}  // namespace nsg::test
