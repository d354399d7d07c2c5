// The readers of an export's documents (frames_documents.h) on crafted files: every mistyped
// or missing field of a manifest or a record is a ParseError naming the file, the JSON pointer
// and what was expected (exit 2, never 3); a listed file is measured — a regular file, no link,
// its size the manifest's — before a byte of it is read; listed paths stay inside the export;
// a results file's mistyped fields are issues (exit 1); --max-seconds stops frame scoring.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <functional>

#include <nlohmann/json.hpp>

#include "frames_export_fixture.h"
#include "nsg/core/error.h"
#include "nsg/metrics/frames.h"
#include "test_support.h"

namespace nsg::metrics {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kGolden = test::source_dir() / "tests/data/golden/frames";

// Runs `read` and returns the error of type E it throws (fails the test when it throws none).
template <class E>
std::optional<E> thrown(const std::function<void()>& read) {
  try {
    read();
  } catch (const E& e) {
    return e;
  }
  ADD_FAILURE() << "no error thrown";
  return std::nullopt;
}

test::CommandResult score_frames_cli(const fs::path& ground_truth, const fs::path& results,
                                     std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"score",        "--quiet",       "--frames", "--ground-truth", ground_truth.string(),
                                   "--submission", results.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run_nsgraph(args);
}

struct Mutation {
  std::string name;
  std::function<void(json&)> change;
  std::string pointer;  // the JSON pointer the error names
};

TEST(FramesManifest, AMistypedOrMissingFieldIsAParseErrorNamingTheFilePointerAndExpectation) {
  test::TempDir tmp("frames-manifest-types");
  const std::vector<Mutation> cases = {
      {"bytes-string", [](json& m) { m["files"][0]["bytes"] = "100"; }, "/files/0/bytes"},
      {"bytes-negative", [](json& m) { m["files"][0]["bytes"] = -1; }, "/files/0/bytes"},
      {"bytes-float", [](json& m) { m["files"][0]["bytes"] = 1e30; }, "/files/0/bytes"},
      {"bytes-beyond-int64", [](json& m) { m["files"][0]["bytes"] = UINT64_MAX; }, "/files/0/bytes"},
      {"bytes-missing", [](json& m) { m["files"][0].erase("bytes"); }, "/files/0/bytes"},
      {"sha256-number", [](json& m) { m["files"][0]["sha256"] = 7; }, "/files/0/sha256"},
      {"sha256-short", [](json& m) { m["files"][0]["sha256"] = "abc"; }, "/files/0/sha256"},
      {"path-number", [](json& m) { m["files"][0]["path"] = 3; }, "/files/0/path"},
      {"file-string", [](json& m) { m["files"][0] = "test/x/info/1.json"; }, "/files/0"},
      {"files-object", [](json& m) { m["files"] = json::object(); }, "/files"},
      {"files-missing", [](json& m) { m.erase("files"); }, "/files"},
      {"kind-missing", [](json& m) { m.erase("kind"); }, "/kind"},
      {"kind-number", [](json& m) { m["kind"] = 1; }, "/kind"},
      {"kind-other", [](json& m) { m["kind"] = "nsgraph-dataset"; }, "/kind"},
      {"schema-version", [](json& m) { m["schema_version"] = 1; }, "/schema_version"},
      {"source-array", [](json& m) { m["source"] = json::array(); }, "/source"},
      {"sha-of-dataset", [](json& m) { m["source"]["dataset_manifest_sha256"] = 5; },
       "/source/dataset_manifest_sha256"},
      {"dataroot-null", [](json& m) { m["source"]["dataroot"] = nullptr; }, "/source/dataroot"},
      {"window-missing", [](json& m) { m["config"].erase("window"); }, "/config/window"},
      {"window-edge-string", [](json& m) { m["config"]["window"]["x_min_m"] = "-50"; }, "/config/window/x_min_m"},
      {"window-empty", [](json& m) { m["config"]["window"]["x_max_m"] = -60.0; }, "/config/window/x_max_m"},
      {"points-fraction", [](json& m) { m["config"]["centerline_points"] = 1.5; }, "/config/centerline_points"},
      {"copy-images-string", [](json& m) { m["config"]["copy_images"] = "no"; }, "/config/copy_images"},
      {"listed-twice", [](json& m) { m["files"].push_back(m["files"][0]); }, "/files/1/path"},
      {"not-an-object", [](json& m) { m = json::array(); }, ""},
  };
  test::write_text(tmp / "results.json", R"({"results": {}})");
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path dir = tmp / c.name;
    json manifest = test::write_one_record_export(dir);
    c.change(manifest);
    test::write_text(dir / "manifest.json", manifest.dump());
    const std::optional<ParseError> e = thrown<ParseError>([&] { read_frames_manifest(dir); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), (dir / "manifest.json").string());
    EXPECT_EQ(e->record(), c.pointer) << e->what();
    EXPECT_FALSE(e->expected().empty());
    // The CLI: exit 2 naming the manifest and the pointer (it was 3, json::exception, before).
    const test::CommandResult r = score_frames_cli(dir, tmp / "results.json");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find((dir / "manifest.json").string() + ": " + c.pointer), std::string::npos) << r.err;
  }
}

TEST(FramesManifest, ListedPathsStayInsideTheExport) {
  test::TempDir tmp("frames-manifest-inside");
  // A valid record outside the export, listed with its true size and sha256.
  const std::string text = test::frame_record_json().dump();
  fs::create_directories(tmp / "outside/info");
  test::write_text(tmp / "outside/info/1.json", text);
  for (const std::string& path : {std::string("test/../../outside/info/1.json"), (tmp / "outside/info/1.json").string(),
                                  std::string("test/x/info/../../../../outside/info/1.json")}) {
    SCOPED_TRACE(path);
    const fs::path dir = tmp / "export";
    json manifest = test::write_one_record_export(dir);
    manifest["files"][0]["path"] = path;
    test::write_text(dir / "manifest.json", manifest.dump());
    const std::optional<ParseError> e = thrown<ParseError>([&] { read_frames_manifest(dir); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->record(), "/files/0/path");
    EXPECT_NE(e->expected().find("inside the export"), std::string::npos) << e->what();
  }
}

TEST(FramesRecord, AMissingOrMistypedFieldIsAParseErrorNamingTheFilePointerAndExpectation) {
  const std::vector<Mutation> cases = {
      {"pose-missing", [](json& r) { r.erase("pose"); }, "/pose"},
      {"pose-string", [](json& r) { r["pose"] = "identity"; }, "/pose"},
      {"rotation-missing", [](json& r) { r["pose"].erase("rotation"); }, "/pose/rotation"},
      {"rotation-2-rows", [](json& r) { r["pose"]["rotation"].erase(2); }, "/pose/rotation"},
      {"rotation-entry", [](json& r) { r["pose"]["rotation"][1][2] = "0"; }, "/pose/rotation/1/2"},
      {"rotation-scaled", [](json& r) { r["pose"]["rotation"][0][0] = 2.0; }, "/pose/rotation/0/0"},
      {"translation-far", [](json& r) { r["pose"]["translation"][0] = 1e300; }, "/pose/translation/0"},
      {"token-number", [](json& r) { r["sample_token"] = 5; }, "/sample_token"},
      {"token-empty", [](json& r) { r["sample_token"] = ""; }, "/sample_token"},
      {"split-other", [](json& r) { r["split"] = "dev"; }, "/split"},
      {"timestamp-string", [](json& r) { r["timestamp"] = "1"; }, "/timestamp"},
      {"version-other", [](json& r) { r["version"] = "nsgraph-frames-3"; }, "/version"},
      {"location-missing", [](json& r) { r["meta_data"].erase("location"); }, "/meta_data/location"},
      {"region-number", [](json& r) { r["meta_data"]["region"] = 3; }, "/meta_data/region"},
      {"camera-number", [](json& r) { r["sensor"]["CAM_FRONT"] = 1; }, "/sensor/CAM_FRONT"},
      {"image-outside", [](json& r) { r["sensor"]["CAM_FRONT"]["image_path"] = "../../etc/passwd"; },
       "/sensor/CAM_FRONT/image_path"},
      {"image-absolute", [](json& r) { r["sensor"]["CAM_FRONT"]["image_path"] = "/etc/passwd"; },
       "/sensor/CAM_FRONT/image_path"},
      {"k-2x3", [](json& r) { r["sensor"]["CAM_FRONT"]["intrinsic"]["K"].erase(2); }, "/sensor/CAM_FRONT/intrinsic/K"},
      {"width-negative", [](json& r) { r["sensor"]["CAM_FRONT"]["width"] = -1; }, "/sensor/CAM_FRONT/width"},
      {"lanes-object", [](json& r) { r["annotation"]["lane_centerline"] = json::object(); },
       "/annotation/lane_centerline"},
      {"points-one",
       [](json& r) {
         json& points = r["annotation"]["lane_centerline"][1]["points"];
         points = json::array({points[0]});
       },
       "/annotation/lane_centerline/1/points"},
      {"point-2d",
       [](json& r) {
         r["annotation"]["lane_centerline"][0]["points_2m"][3] = {1.0, 2.0};
       },
       "/annotation/lane_centerline/0/points_2m/3"},
      {"connector-string",
       [](json& r) { r["annotation"]["lane_centerline"][0]["is_intersection_or_connector"] = "no"; },
       "/annotation/lane_centerline/0/is_intersection_or_connector"},
      {"id-negative", [](json& r) { r["annotation"]["lane_centerline"][0]["id"] = -2; },
       "/annotation/lane_centerline/0/id"},
      {"topology-rows", [](json& r) { r["annotation"]["topology_lclc"].erase(1); }, "/annotation/topology_lclc"},
      {"topology-value", [](json& r) { r["annotation"]["topology_lclc"][0][1] = 2; }, "/annotation/topology_lclc/0/1"},
      {"topology-missing", [](json& r) { r["annotation"].erase("topology_lclc"); }, "/annotation/topology_lclc"},
      {"lcte-rows", [](json& r) { r["annotation"]["topology_lcte"] = json::array(); }, "/annotation/topology_lcte"},
      {"annotation-missing", [](json& r) { r.erase("annotation"); }, "/annotation"},
      {"not-an-object", [](json& r) { r = json::array(); }, ""},
  };
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    json record = test::frame_record_json();
    c.change(record);
    const std::optional<ParseError> e = thrown<ParseError>([&] { read_frame_record(record.dump(), "r.json"); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), "r.json");
    EXPECT_EQ(e->record(), c.pointer) << e->what();
    EXPECT_FALSE(e->expected().empty());
  }
  // Beyond the format's nesting, a repeated key, not JSON: named too, with no recursion.
  for (const std::string& text : {std::string(100000, '[') + std::string(100000, ']'),
                                  std::string(R"({"pose": 1, "pose": 2})"), std::string("{\"pose\": NaN}")}) {
    const std::optional<ParseError> e = thrown<ParseError>([&] { read_frame_record(text, "r.json"); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), "r.json");
  }
  // The fixture itself reads, as the scorer sees it.
  const FrameRecord r = read_frame_record(test::frame_record_json().dump(), "r.json");
  EXPECT_EQ(r.sample_token, "tok");
  EXPECT_EQ(r.cameras.at(0).channel, "CAM_FRONT");
  EXPECT_EQ(r.truth().topology, (std::vector<double>{0, 1, 0, 0}));
  EXPECT_EQ(r.centerlines.at(1).points_2m.size(), 21u);
}

// Version 2: the lane segments and areas are read with every field typed, one lane segment
// per centerline with its id; a version-1 record (above) still reads without them.
TEST(FramesRecord, AVersion2RecordCarriesLaneSegmentsAndAreasEachChecked) {
  const FrameRecord r = read_frame_record(test::frame_record_v2_json().dump(), "r.json");
  ASSERT_EQ(r.lane_segments.size(), 2u);
  EXPECT_EQ(r.lane_segments[1].id, 1000);
  EXPECT_EQ(r.lane_segments[0].left_type, 1);
  EXPECT_EQ(r.lane_segments[0].left_laneline.at(0)[1], 1.75);
  EXPECT_TRUE(r.lane_segments[1].is_connector);
  ASSERT_EQ(r.areas.size(), 2u);
  EXPECT_EQ(r.areas[0].category, 1);
  EXPECT_EQ(r.areas[1].points.size(), 2u);
  EXPECT_EQ(r.topology_lsls, (std::vector<uint8_t>{0, 1, 0, 0}));
  EXPECT_TRUE(read_frame_record(test::frame_record_json().dump(), "r.json").lane_segments.empty());

  struct Mutation {
    const char* name;
    std::function<void(json&)> change;
    const char* pointer;
  };
  const std::vector<Mutation> cases = {
      {"segments-missing", [](json& r) { r["annotation"].erase("lane_segment"); }, "/annotation/lane_segment"},
      {"segments-fewer", [](json& r) { r["annotation"]["lane_segment"].erase(1); }, "/annotation/lane_segment"},
      {"segment-id", [](json& r) { r["annotation"]["lane_segment"][1]["id"] = 7; }, "/annotation/lane_segment/1/id"},
      {"type-3", [](json& r) { r["annotation"]["lane_segment"][0]["right_laneline_type"] = 3; },
       "/annotation/lane_segment/0/right_laneline_type"},
      {"laneline-one-point",
       [](json& r) {
         json& l = r["annotation"]["lane_segment"][0]["left_laneline"];
         l = json::array({l[0]});
       },
       "/annotation/lane_segment/0/left_laneline"},
      {"area-category", [](json& r) { r["annotation"]["area"][0]["category"] = 0; }, "/annotation/area/0/category"},
      {"area-points", [](json& r) { r["annotation"]["area"][1]["points"][0] = {1.0}; }, "/annotation/area/1/points/0"},
      {"lsls-value", [](json& r) { r["annotation"]["topology_lsls"][1][0] = 0.5; }, "/annotation/topology_lsls/1/0"},
      {"lste-missing", [](json& r) { r["annotation"].erase("topology_lste"); }, "/annotation/topology_lste"},
  };
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    json record = test::frame_record_v2_json();
    c.change(record);
    const std::optional<ParseError> e = thrown<ParseError>([&] { read_frame_record(record.dump(), "r.json"); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->record(), c.pointer) << e->what();
  }
}

TEST(FramesRecord, ADefectiveListedRecordExitsTwoNamingItsFileAndPointer) {
  test::TempDir tmp("frames-record-cli");
  json record = test::frame_record_json();
  record["annotation"]["lane_centerline"][0]["points"][2][1] = "x";
  test::write_one_record_export(tmp / "export", record);
  test::write_text(tmp / "results.json", R"({"results": {}})");
  const test::CommandResult r = score_frames_cli(tmp / "export", tmp / "results.json");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(test::kFixtureRecordPath), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/annotation/lane_centerline/0/points/2/1"), std::string::npos) << r.err;
  // A record under test/ that says it is a train frame.
  test::write_one_record_export(tmp / "split", test::frame_record_json("tok", "train"));
  const std::optional<DataError> e =
      thrown<DataError>([&] { read_frames_ground_truth(tmp / "split", "test", /*verify=*/true); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->record(), "/split");
}

TEST(FramesExport, AListedFileIsMeasuredBeforeItIsRead) {
  test::TempDir tmp("frames-measured");
  const fs::path record = fs::path(test::kFixtureRecordPath);
  const auto fresh = [&](const std::string& name) {
    test::write_one_record_export(tmp / name);
    fs::remove(tmp / name / record);
    return tmp / name;
  };
  const auto read = [](const fs::path& dir) { read_frames_ground_truth(dir, "test", /*verify=*/true); };
  const auto started = std::chrono::steady_clock::now();
  // A link to /dev/zero (endless): refused as a link, nothing read.
  const fs::path zero = fresh("zero");
  fs::create_symlink("/dev/zero", zero / record);
  std::optional<DataError> e = thrown<DataError>([&] { read(zero); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), (zero / record).string());
  EXPECT_NE(e->expected().find("symbolic link"), std::string::npos) << e->what();
  // A link to a valid record outside the export, of the listed size and sha256.
  const fs::path linked = fresh("linked");
  test::write_text(tmp / "elsewhere.json", test::frame_record_json().dump());
  fs::create_symlink(tmp / "elsewhere.json", linked / record);
  e = thrown<DataError>([&] { read(linked); });
  ASSERT_TRUE(e);
  EXPECT_NE(e->expected().find("symbolic link"), std::string::npos) << e->what();
  // A folder on the path that is a link out of the export.
  const fs::path folder = fresh("folder");
  fs::create_directories(tmp / "outside");
  test::write_text(tmp / "outside/1.json", test::frame_record_json().dump());
  fs::remove_all(folder / record.parent_path());
  fs::create_directory_symlink(tmp / "outside", folder / record.parent_path());
  e = thrown<DataError>([&] { read(folder); });
  ASSERT_TRUE(e);
  EXPECT_NE(e->expected().find("symbolic link"), std::string::npos) << e->what();
  // A FIFO: refused without blocking on it.
  const fs::path fifo = fresh("fifo");
  ASSERT_EQ(::mkfifo((fifo / record).c_str(), 0600), 0);
  e = thrown<DataError>([&] { read(fifo); });
  ASSERT_TRUE(e);
  EXPECT_NE(e->expected().find("regular file"), std::string::npos) << e->what();
  // A file longer or shorter than listed.
  for (const std::string& tail : {std::string(" "), std::string()}) {
    const fs::path sized = tmp / ("sized" + std::to_string(tail.size()));
    const std::string text = test::frame_record_json().dump();
    test::write_one_record_export(sized);
    test::write_text(sized / record, tail.empty() ? text.substr(0, text.size() - 1) : text + tail);
    e = thrown<DataError>([&] { read(sized); });
    ASSERT_TRUE(e);
    EXPECT_NE(e->expected().find("size"), std::string::npos) << e->what();
  }
  // Beyond the format's limit, though listed with that size.
  const fs::path big = tmp / "big";
  test::write_one_record_export(big);
  const FramesManifest m = read_frames_manifest(big);
  FramesDocumentLimits small;
  small.max_record_bytes = 100;
  e = thrown<DataError>([&] { read_listed_record(m, m.files.at(0), true, small); });
  ASSERT_TRUE(e);
  EXPECT_NE(e->expected().find("at most 100 bytes"), std::string::npos) << e->what();
  // The manifest itself: a link to /dev/zero is measured (not a regular file), not read.
  const fs::path zero_manifest = tmp / "zero-manifest";
  fs::create_directories(zero_manifest);
  fs::create_symlink("/dev/zero", zero_manifest / "manifest.json");
  e = thrown<DataError>([&] { read_frames_manifest(zero_manifest); });
  ASSERT_TRUE(e);
  EXPECT_NE(e->expected().find("regular file"), std::string::npos) << e->what();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(), 5.0);
}

TEST(FramesExport, ARecordLargerThanListedIsRefusedWithoutReadingIt) {
  test::TempDir tmp("frames-sparse");
  const fs::path dir = tmp / "export";
  test::write_one_record_export(dir);
  // 1 GiB, sparse: the old reader read it whole (peak memory > 1 GiB) before comparing sizes.
  fs::resize_file(dir / test::kFixtureRecordPath, uint64_t{1} << 30);
  test::write_text(tmp / "results.json", R"({"results": {}})");
  const test::CommandResult r = score_frames_cli(dir, tmp / "results.json");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("size"), std::string::npos) << r.err;
  EXPECT_LT(r.peak_rss_bytes, uint64_t{256} << 20);
}

TEST(FramesResults, AMistypedFieldIsAnIssueNeverAnException) {
  test::TempDir tmp("frames-results-types");
  const json lane = {{"id", 0}, {"points", {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}}, {"confidence", 0.5}};
  const json valid = {
      {"results", {{"tok", {{"predictions", {{"lane_centerline", {lane}}, {"topology_lclc", {{0}}}}}}}}}};
  const std::vector<Mutation> cases = {
      {"results-array", [](json& d) { d["results"] = json::array(); }, ""},
      {"results-string", [](json& d) { d["results"] = "x"; }, ""},
      {"document-number", [](json& d) { d = 3; }, ""},
      {"frame-string", [](json& d) { d["results"]["tok"] = "x"; }, "/results/tok"},
      {"predictions-number", [](json& d) { d["results"]["tok"]["predictions"] = 1; }, "/results/tok"},
      {"lanes-object", [](json& d) { d["results"]["tok"]["predictions"]["lane_centerline"] = json::object(); },
       "/results/tok/predictions/lane_centerline"},
      {"lane-string", [](json& d) { d["results"]["tok"]["predictions"]["lane_centerline"][0] = "x"; },
       "/results/tok/predictions/lane_centerline/0"},
      {"points-string", [](json& d) { d["results"]["tok"]["predictions"]["lane_centerline"][0]["points"] = "x"; },
       "/results/tok/predictions/lane_centerline/0"},
      {"point-string", [](json& d) { d["results"]["tok"]["predictions"]["lane_centerline"][0]["points"][1] = "x"; },
       "/results/tok/predictions/lane_centerline/0/points/1"},
      {"coordinate-null",
       [](json& d) { d["results"]["tok"]["predictions"]["lane_centerline"][0]["points"][1][2] = nullptr; },
       "/results/tok/predictions/lane_centerline/0/points/1"},
      {"confidence-string",
       [](json& d) { d["results"]["tok"]["predictions"]["lane_centerline"][0]["confidence"] = "0.5"; },
       "/results/tok/predictions/lane_centerline/0/confidence"},
      {"confidence-bool",
       [](json& d) { d["results"]["tok"]["predictions"]["lane_centerline"][0]["confidence"] = true; },
       "/results/tok/predictions/lane_centerline/0/confidence"},
      {"topology-string", [](json& d) { d["results"]["tok"]["predictions"]["topology_lclc"] = "x"; },
       "/results/tok/predictions/topology_lclc"},
      {"topology-row-number", [](json& d) { d["results"]["tok"]["predictions"]["topology_lclc"][0] = 0; },
       "/results/tok/predictions/topology_lclc/0"},
      {"topology-value-bool", [](json& d) { d["results"]["tok"]["predictions"]["topology_lclc"][0][0] = false; },
       "/results/tok/predictions/topology_lclc/0/0"},
      {"topology-missing", [](json& d) { d["results"]["tok"]["predictions"].erase("topology_lclc"); },
       "/results/tok/predictions/topology_lclc"},
  };
  for (const Mutation& c : cases) {
    SCOPED_TRACE(c.name);
    json doc = valid;
    c.change(doc);
    test::write_text(tmp / (c.name + ".json"), doc.dump());
    Issues issues;
    std::optional<FrameSet> read;
    EXPECT_NO_THROW(read = read_frames_results(tmp / (c.name + ".json"), FrameResultsLimits{}, issues));
    EXPECT_FALSE(read);
    ASSERT_FALSE(issues.empty());
    EXPECT_EQ(issues.items()[0].subject, (tmp / (c.name + ".json")).string() + ":" + c.pointer) << issues.format();
  }
  // Through the CLI: problems (exit 1), not an internal error.
  const test::CommandResult r = score_frames_cli(kGolden / "gt.json", tmp / "confidence-string.json");
  EXPECT_EQ(r.exit_code, 1) << r.err;
}

TEST(ScoreFrames, MaxSecondsStopsTheRunByName) {
  const FrameSet truth = read_frames_ground_truth_document(kGolden / "gt.json");
  ASSERT_GT(truth.size(), 1u);
  FrameSet copy = truth;  // a prediction carries a confidence per centerline
  for (auto& [key, f] : copy) f.confidence.assign(f.lanes.size(), 1.0);
  const std::optional<ConfigError> e = thrown<ConfigError>([&] { score_frames(truth, copy, false, 1e-9); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->record(), "--max-seconds");
  EXPECT_NE(e->expected().find("frames within"), std::string::npos) << e->what();
  EXPECT_EQ(score_frames(truth, copy, false, 0).det_l, 1.0);  // 0: no limit
  FramesScoreInput in;
  in.ground_truth = kGolden / "gt.json";
  in.results = kGolden / "pred.json";
  in.max_seconds = 1e-9;
  EXPECT_THROW(score_frames_submission(in), ConfigError);
  in.max_seconds = std::nan("");
  EXPECT_THROW(score_frames_submission(in), ConfigError);
  // The CLI's --max-seconds reaches it: exit 2 naming the flag; 0 scores.
  const test::CommandResult r = score_frames_cli(kGolden / "gt.json", kGolden / "pred.json", {"--max-seconds", "1e-9"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--max-seconds"), std::string::npos) << r.err;
  EXPECT_EQ(score_frames_cli(kGolden / "gt.json", kGolden / "pred.json", {"--max-seconds", "0"}).exit_code, 0);
}

}  // namespace
}  // namespace nsg::metrics
