// The corruption catalogue: each case damages one thing in a private copy of the
// synthetic release (or a detections / submission file), runs the command that reads it and
// asserts a clean refusal: the expected exit code (never a signal), stderr naming the file
// and the record, and no partial output in --out (no manifest, no shard, no temp file).
// Map defects the design reports instead of refusing are checked on that path.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <functional>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "release_copy.h"
#include "test_support.h"

namespace fs = std::filesystem;
// Tables keep their key order ("token" first, as in nuScenes files) when edited.
using json = nlohmann::ordered_json;

namespace nsg::test {
namespace {

// A token no table holds (valid 32-hex text, so only the link check can refuse it).
const std::string kBogus = "0badf00d0badf00d0badf00d0badf00d";
const std::string kBogusMap = "0badf00d-0bad-f00d-0bad-f00d0badf00d";
const std::string kMap = "maps/expansion/boston-seaport.json";
const std::string kDetections = "detections/synthetic_detector.json";

enum class Command { kGenerate, kGenerateStrict, kGenerateDetections, kValidateSubmission, kScore };

// What a case sets up and expects; `corrupt` fills `expect` with data-dependent text.
struct Scenario {
  explicit Scenario(ReleaseCopy& r) : release(r) {}
  ReleaseCopy& release;
  Command command = Command::kGenerate;
  int exit_code = 2;
  std::vector<std::string> expect;  // substrings of stderr: the file, the record, the value
  std::string submission;           // text of the submission file (submission commands)
  bool output_expected = false;     // the reported-defect path: generate completes
  int map_defects = -1;             // ≥ 0: the count the manifest must record
};

struct Case {
  std::string name;
  std::function<void(Scenario&)> corrupt;
};

// gtest prints the case by name (not as bytes) in test names and failures.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// ---- helpers building cases -------------------------------------------------------------

// Sets table[row][field] = value and expects the table file, the row's token and `field`.
Case set_field(const std::string& name, const std::string& table, size_t row, const std::string& field, json value,
               std::vector<std::pair<std::string, std::string>> text_edits = {}, bool expect_value = false) {
  return {name, [=](Scenario& s) {
            json rows = s.release.table(table);
            rows.at(row).at(field) = value;
            s.release.put_table(table, rows, text_edits);
            s.expect = {table + ".json", rows[row]["token"].get<std::string>()};
            if (expect_value) s.expect.push_back(value.get<std::string>());
          }};
}

// A link to a row that does not exist.
Case dangling(const std::string& table, size_t row, const std::string& field) {
  Case c = set_field("dangling_" + table + "_" + field, table, row, field, kBogus, {}, true);
  return c;
}

// Non-finite value spliced into a number array: table[row][field][k] = NaN/Infinity.
Case non_finite(const std::string& name, const std::string& table, size_t row, const std::string& field, size_t k,
                const std::string& literal) {
  return {name, [=](Scenario& s) {
            json rows = s.release.table(table);
            rows.at(row).at(field).at(k) = "@NONFINITE@";
            s.release.put_table(table, rows, {{"\"@NONFINITE@\"", literal}});
            s.expect = {table + ".json", rows[row]["token"].get<std::string>()};
          }};
}

// Edits the map expansion JSON document.
Case map_edit(const std::string& name, const std::function<std::string(json&)>& edit,
              Command command = Command::kGenerate, int exit_code = 2) {
  return {name, [=](Scenario& s) {
            json map = json::parse(s.release.read(kMap));
            const std::string record = edit(map);
            s.release.write(kMap, map.dump());
            s.command = command;
            s.exit_code = exit_code;
            s.expect = {"boston-seaport.json", record};
          }};
}

// Edits the detection results and runs generate --detections.
Case detections_edit(const std::string& name, const std::function<std::string(json&)>& edit) {
  return {name, [=](Scenario& s) {
            json doc = json::parse(s.release.read(kDetections));
            const std::string record = edit(doc);
            s.release.write(kDetections, doc.dump());
            s.command = Command::kGenerateDetections;
            s.expect = {"synthetic_detector.json", record};
          }};
}

// The first lidar key frame of the release: read by every generate run.
std::string first_lidar_file(const ReleaseCopy& r) {
  return r.sample_data("pcd", true, "samples/LIDAR_TOP/")["filename"].get<std::string>();
}

void put_float(std::string& bytes, size_t float_index, float value) {
  std::memcpy(bytes.data() + float_index * 4, &value, 4);
}

// The semantic mask of a camera image: semantic/<channel>/<stem>.png.
std::string mask_of(const std::string& jpg) {
  std::string m = "semantic/" + jpg.substr(std::strlen("samples/"));
  return m.substr(0, m.size() - 4) + ".png";
}

std::string submission_text() {
  // A well-formed submission of one empty tile (the cases break it).
  return R"({"schema_version": "1", "tiles": {"x": {"nodes": [[1.0, 2.0]], "edges": []}}})";
}

// ---- the catalogue -----------------------------------------------------------------------

std::vector<Case> catalogue() {
  std::vector<Case> cases;
  // Broken, truncated, wrong-typed tables.
  cases.push_back({"truncated_sample_data_json", [](Scenario& s) {
                     const std::string text = s.release.read("v1.0-mini/sample_data.json");
                     s.release.write("v1.0-mini/sample_data.json", text.substr(0, text.size() / 2));
                     s.expect = {"sample_data.json", "truncated"};
                   }});
  cases.push_back({"broken_json_scene", [](Scenario& s) {
                     std::string text = s.release.read("v1.0-mini/scene.json");
                     text.insert(text.find("\"log_token\""), "}},{,");
                     s.release.write("v1.0-mini/scene.json", text);
                     s.expect = {"scene.json", "record"};
                   }});
  cases.push_back({"empty_ego_pose_file", [](Scenario& s) {
                     s.release.write("v1.0-mini/ego_pose.json", "");
                     s.expect = {"ego_pose.json"};
                   }});
  cases.push_back(set_field("wrong_type_sample_timestamp", "sample", 3, "timestamp", "1532402927647951"));
  cases.push_back(set_field("wrong_type_sample_data_is_key_frame", "sample_data", 5, "is_key_frame", 1));
  cases.push_back(set_field("wrong_type_scene_nbr_samples", "scene", 1, "nbr_samples", json::array({5})));
  cases.push_back(set_field("wrong_type_annotation_size", "sample_annotation", 2, "size", "large"));
  cases.push_back({"wrong_type_before_token_key", [](Scenario& s) {
                     // Keys may come in any order: a bad value read before "token" still names
                     // the record's token (found by scanning the record's text).
                     json rows = s.release.table("sample");
                     json moved = {{"timestamp", "soon"}};
                     for (auto& [k, v] : rows[4].items())
                       if (k != "timestamp") moved[k] = v;
                     rows[4] = moved;
                     s.release.put_table("sample", rows);
                     s.expect = {"sample.json", "record 4", "timestamp", rows[4]["token"].get<std::string>()};
                   }});
  cases.push_back(set_field("wrong_arity_ego_pose_rotation", "ego_pose", 7, "rotation", json::array({1.0, 0.0, 0.0})));
  // NaN / Infinity in poses, calibrations, boxes.
  cases.push_back(non_finite("nan_ego_pose_translation", "ego_pose", 10, "translation", 0, "NaN"));
  cases.push_back(non_finite("inf_ego_pose_rotation", "ego_pose", 11, "rotation", 3, "Infinity"));
  cases.push_back(non_finite("nan_calibrated_sensor_translation", "calibrated_sensor", 0, "translation", 2, "NaN"));
  cases.push_back(non_finite("inf_calibrated_sensor_rotation", "calibrated_sensor", 1, "rotation", 0, "-Infinity"));
  cases.push_back(non_finite("nan_annotation_translation", "sample_annotation", 4, "translation", 1, "NaN"));
  // Dangling tokens, table by table.
  cases.push_back(dangling("sample", 2, "scene_token"));
  cases.push_back(dangling("sample", 2, "next"));
  cases.push_back(dangling("sample_data", 8, "sample_token"));
  cases.push_back(dangling("sample_data", 9, "ego_pose_token"));
  cases.push_back(dangling("sample_data", 10, "calibrated_sensor_token"));
  cases.push_back(dangling("sample_data", 11, "prev"));
  cases.push_back(dangling("calibrated_sensor", 3, "sensor_token"));
  cases.push_back(dangling("scene", 1, "log_token"));
  cases.push_back(dangling("scene", 2, "first_sample_token"));
  cases.push_back(dangling("sample_annotation", 6, "instance_token"));
  cases.push_back(dangling("sample_annotation", 7, "sample_token"));
  cases.push_back(dangling("instance", 1, "category_token"));
  cases.push_back(dangling("instance", 2, "first_annotation_token"));
  cases.push_back({"dangling_map_log_tokens", [](Scenario& s) {
                     json rows = s.release.table("map");
                     rows[0]["log_tokens"][1] = kBogus;
                     s.release.put_table("map", rows);
                     s.expect = {"map.json", kBogus};
                   }});
  cases.push_back({"dangling_annotation_attribute", [](Scenario& s) {
                     json rows = s.release.table("sample_annotation");
                     rows[0]["attribute_tokens"] = json::array({kBogus});
                     s.release.put_table("sample_annotation", rows);
                     s.expect = {"sample_annotation.json", rows[0]["token"].get<std::string>(), kBogus};
                   }});
  // An empty scene: no samples at all.
  cases.push_back({"empty_scene", [](Scenario& s) {
                     json rows = s.release.table("scene");
                     json scene = rows[0];
                     scene["token"] = kBogus;
                     scene["name"] = "scene-empty";
                     scene["nbr_samples"] = 0;
                     scene["first_sample_token"] = "";
                     scene["last_sample_token"] = "";
                     rows.push_back(scene);
                     s.release.put_table("scene", rows);
                     s.expect = {"scene.json", kBogus};
                   }});
  // Missing files.
  cases.push_back({"missing_table_instance", [](Scenario& s) {
                     s.release.remove("v1.0-mini/instance.json");
                     s.expect = {"instance.json"};
                   }});
  cases.push_back({"missing_map_expansion", [](Scenario& s) {
                     s.release.remove(kMap);
                     s.expect = {"boston-seaport.json"};
                   }});
  cases.push_back({"missing_lidar_sweep", [](Scenario& s) {
                     const std::string file = s.release.sample_data("pcd", false, "sweeps/LIDAR_TOP/")["filename"];
                     s.release.remove(file);
                     s.expect = {file};
                   }});
  cases.push_back({"missing_lidar_key_frame", [](Scenario& s) {
                     const std::string file = first_lidar_file(s.release);
                     s.release.remove(file);
                     s.expect = {file};
                   }});
  cases.push_back({"missing_jpegs", [](Scenario& s) {
                     // Every key-frame image of one channel: whichever one the run needs first.
                     for (const std::string& f : s.release.key_frame_files("samples/CAM_FRONT/")) s.release.remove(f);
                     s.expect = {"samples/CAM_FRONT/", ".jpg"};
                   }});
  // Damaged LiDAR sweeps.
  cases.push_back({"truncated_pcd_bin", [](Scenario& s) {
                     const std::string file = first_lidar_file(s.release);
                     s.release.write(file, s.release.read(file).substr(0, 20 * 100 + 7));
                     s.expect = {file, "20"};
                   }});
  cases.push_back({"misaligned_pcd_bin", [](Scenario& s) {
                     const std::string file = first_lidar_file(s.release);
                     s.release.write(file, s.release.read(file) + "abc");
                     s.expect = {file, "20"};
                   }});
  cases.push_back({"empty_pcd_bin_of_sweep", [](Scenario& s) {
                     // An empty sweep is legal (0 points); the run must still complete.
                     const std::string file = s.release.sample_data("pcd", false, "sweeps/LIDAR_TOP/")["filename"];
                     s.release.write(file, "");
                     s.exit_code = 0;
                     s.output_expected = true;
                   }});
  cases.push_back({"nan_in_points", [](Scenario& s) {
                     const std::string file = first_lidar_file(s.release);
                     std::string bytes = s.release.read(file);
                     put_float(bytes, 5 * 123 + 1, std::numeric_limits<float>::quiet_NaN());  // point 123, y
                     s.release.write(file, bytes);
                     s.expect = {file, "123"};
                   }});
  cases.push_back({"inf_in_points", [](Scenario& s) {
                     const std::string file = first_lidar_file(s.release);
                     std::string bytes = s.release.read(file);
                     put_float(bytes, 5 * 77 + 3, -std::numeric_limits<float>::infinity());  // point 77, intensity
                     s.release.write(file, bytes);
                     s.expect = {file, "77"};
                   }});
  cases.push_back({"nan_in_ring_of_last_point", [](Scenario& s) {
                     // The ring column, in the last run of rows the sweep loop reads.
                     const std::string file = first_lidar_file(s.release);
                     std::string bytes = s.release.read(file);
                     const size_t last = bytes.size() / 20 - 1;
                     put_float(bytes, 5 * last + 4, std::numeric_limits<float>::quiet_NaN());
                     s.release.write(file, bytes);
                     s.expect = {file, "point " + std::to_string(last)};
                   }});
  // Damaged camera images and semantic masks (every key frame of a channel, see above).
  cases.push_back({"jpeg_cut_in_half", [](Scenario& s) {
                     for (const std::string& f : s.release.key_frame_files("samples/CAM_FRONT/")) {
                       const std::string bytes = s.release.read(f);
                       s.release.write(f, bytes.substr(0, bytes.size() / 2));
                     }
                     s.expect = {"samples/CAM_FRONT/", ".jpg"};
                   }});
  cases.push_back({"jpeg_not_an_image", [](Scenario& s) {
                     for (const std::string& f : s.release.key_frame_files("samples/CAM_BACK/"))
                       s.release.write(f, "this is not a JPEG");
                     s.expect = {"samples/CAM_BACK/", ".jpg"};
                   }});
  cases.push_back({"semantic_mask_wrong_size", [](Scenario& s) {
                     // A valid 8-bit grayscale PNG of another size: the release's 600×600 basemap.
                     const std::string png = s.release.read("maps/basemap/boston-seaport.png");
                     for (const std::string& f : s.release.key_frame_files("samples/CAM_FRONT/"))
                       s.release.write(mask_of(f), png);
                     s.expect = {"semantic/CAM_FRONT/", ".png", "1600"};
                   }});
  cases.push_back({"semantic_mask_not_png", [](Scenario& s) {
                     for (const std::string& f : s.release.key_frame_files("samples/CAM_BACK/"))
                       s.release.write(mask_of(f), "\x89PNG\r\n\x1a\n garbage");
                     s.expect = {"semantic/CAM_BACK/", ".png"};
                   }});
  // The map expansion.
  cases.push_back({"truncated_map_json", [](Scenario& s) {
                     const std::string text = s.release.read(kMap);
                     s.release.write(kMap, text.substr(0, text.size() * 2 / 3));
                     s.expect = {"boston-seaport.json"};
                   }});
  cases.push_back(map_edit("map_dangling_line_node", [](json& m) {
    m["line"][0]["node_tokens"][0] = kBogusMap;
    return m["line"][0]["token"].get<std::string>();
  }));
  cases.push_back(map_edit("map_wrong_type_node_x", [](json& m) {
    m["node"][3]["x"] = "12.5";
    return m["node"][3]["token"].get<std::string>();
  }));
  cases.push_back(map_edit("map_dangling_lane_polygon", [](json& m) {
    m["lane"][0]["polygon_token"] = kBogusMap;
    return m["lane"][0]["token"].get<std::string>();
  }));
  // Dangling connectivity is a reported map defect: a warning by default, an error with --strict.
  const auto dangling_connectivity = [](json& m) {
    auto it = m["connectivity"].begin();
    it.value()["outgoing"].push_back(kBogusMap);
    return it.key();
  };
  cases.push_back(map_edit("map_dangling_connectivity_strict", dangling_connectivity, Command::kGenerateStrict));
  Case reported = map_edit("map_dangling_connectivity_reported", dangling_connectivity, Command::kGenerate, 0);
  cases.push_back({reported.name, [c = reported.corrupt](Scenario& s) {
                     c(s);
                     s.output_expected = true;
                     s.map_defects = 1;  // the one dangling outgoing token
                     s.expect.clear();   // --quiet: no warning line; the manifest counts it
                   }});
  // Detection results (generate --detections).
  Case unknown_sample = detections_edit("detections_unknown_sample", [](json& d) {
    json boxes = d["results"].begin().value();
    for (json& b : boxes) b["sample_token"] = kBogus;
    d["results"][kBogus] = boxes;
    return kBogus;
  });
  cases.push_back(unknown_sample);
  cases.push_back(detections_edit("detections_score_out_of_range", [](json& d) {
    d["results"].begin().value()[0]["detection_score"] = 1.5;
    return d["results"].begin().key();
  }));
  cases.push_back(detections_edit("detections_unknown_class", [](json& d) {
    d["results"].begin().value()[0]["detection_name"] = "spaceship";
    return d["results"].begin().key();
  }));
  cases.push_back({"detections_truncated", [](Scenario& s) {
                     const std::string text = s.release.read(kDetections);
                     s.release.write(kDetections, text.substr(0, text.size() / 2));
                     s.command = Command::kGenerateDetections;
                     s.expect = {"synthetic_detector.json"};
                   }});
  // Submissions (validate --submission, score): invalid submissions exit 1 (docs/architecture.md, exit codes).
  cases.push_back({"submission_truncated_validate", [](Scenario& s) {
                     const std::string t = submission_text();
                     s.submission = t.substr(0, t.size() / 2);
                     s.command = Command::kValidateSubmission;
                     s.exit_code = 1;
                     s.expect = {"submission.json"};
                   }});
  cases.push_back({"submission_nan_score", [](Scenario& s) {
                     // Not JSON at all: an invalid submission (1), as validate --submission says.
                     s.submission = R"({"schema_version": "1", "tiles": {"x": {"nodes": [[NaN, 2.0]], "edges": []}}})";
                     s.command = Command::kScore;
                     s.exit_code = 1;
                     s.expect = {"submission.json"};
                   }});
  cases.push_back({"submission_wrong_type_score", [](Scenario& s) {
                     s.submission = R"({"schema_version": "1", "tiles": {"x": {"nodes": "none", "edges": []}}})";
                     s.command = Command::kScore;
                     s.exit_code = 1;
                     s.expect = {"submission.json", "x"};
                   }});
  return cases;
}

// ---- the check ---------------------------------------------------------------------------

// Files of `dir` (recursive) whose relative path satisfies `pred`.
std::vector<std::string> files_where(const fs::path& dir, const std::function<bool(const std::string&)>& pred) {
  std::vector<std::string> found;
  if (!fs::exists(dir)) return found;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(e.path(), dir).generic_string();
    if (pred(rel)) found.push_back(rel);
  }
  return found;
}

// The first value of `key` anywhere in the document (depth first), null if none.
nlohmann::json find_key(const nlohmann::json& doc, const std::string& key) {
  if (doc.is_object() && doc.contains(key)) return doc[key];
  if (doc.is_structured())
    for (const auto& child : doc)
      if (nlohmann::json v = find_key(child, key); !v.is_null()) return v;
  return nullptr;
}

class Corruption : public ::testing::TestWithParam<Case> {};

TEST_P(Corruption, RefusedCleanly) {
  const Case& c = GetParam();
  TempDir tmp("corrupt-" + c.name);
  ReleaseCopy release(e2e_release(), tmp / "release");
  Scenario s{release};
  c.corrupt(s);
  const fs::path out = tmp / "out";

  std::vector<std::string> args;
  if (s.command == Command::kValidateSubmission || s.command == Command::kScore) {
    const fs::path sub = tmp / "submission.json";
    write_text(sub, s.submission);
    if (s.command == Command::kValidateSubmission)
      args = {"validate", "--submission", sub.string(), "--dataset", e2e_dataset().string()};
    else
      args = {"score",      "--ground-truth", e2e_dataset().string(),       "--submission",
              sub.string(), "--out",          (out / "score.json").string()};
  } else {
    args = e2e_generate_args(out);
    args[std::find(args.begin(), args.end(), "--dataroot") - args.begin() + 1] = release.root().string();
    if (s.command == Command::kGenerateStrict) args.push_back("--strict");
    if (s.command == Command::kGenerateDetections)
      args.insert(args.end(), {"--detections", (release.root() / kDetections).string()});
  }
  const CommandResult r = run_nsgraph(args);

  EXPECT_LT(r.exit_code, 128) << "killed by signal " << r.exit_code - 128 << "\n" << r.err;
  EXPECT_EQ(r.exit_code, s.exit_code) << r.err;
  if (s.exit_code != 0) {
    // validate prints its report (the issues) on stdout; everything else errs on stderr.
    const std::string& message = s.command == Command::kValidateSubmission ? r.out : r.err;
    EXPECT_FALSE(message.empty());
    for (const std::string& text : s.expect)
      EXPECT_NE(message.find(text), std::string::npos) << "message lacks '" << text << "':\n" << message;
  }
  // No temp file left behind, ever; no manifest or shard from a refused run.
  EXPECT_EQ(files_where(out, [](const std::string& rel) { return rel.find(".tmp-") != std::string::npos; }),
            std::vector<std::string>{});
  if (s.output_expected) {
    EXPECT_TRUE(fs::exists(out / "manifest.json"));
    if (s.map_defects >= 0) {
      EXPECT_EQ(find_key(read_json(out / "manifest.json"), "map_defects"), s.map_defects);
    }
  } else {
    EXPECT_FALSE(fs::exists(out / "manifest.json"));
    EXPECT_EQ(files_where(out, [](const std::string& rel) { return rel.rfind("shards/", 0) == 0; }),
              std::vector<std::string>{});
    EXPECT_FALSE(fs::exists(out / "score.json"));
  }
}

INSTANTIATE_TEST_SUITE_P(Catalogue, Corruption, ::testing::ValuesIn(catalogue()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

TEST(CorruptionCatalogue, HasAtLeastThirtyCases) { EXPECT_GE(catalogue().size(), 30u); }

}  // namespace
}  // namespace nsg::test
