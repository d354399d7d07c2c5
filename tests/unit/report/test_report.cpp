// `nsgraph report` end to end on the e2e dataset: the files written, the scores equal to
// `nsgraph score`'s, the marks on tiles with known defects, the baseline's paired
// differences, the dataset-only mode, bad inputs, determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <map>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/graph/clip.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/measure.h"
#include "nsg/report/report.h"
#include "report_fixture.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

TEST(PairedDifference, KnownValues) {
  // Differences 1, 2, 3 (the undefined pair is skipped): mean 2, sd 1, SE 1/√3.
  const report::PairedDifference d = report::paired_difference({3.0, 5.0, std::nullopt, 7.0}, {2.0, 3.0, 1.0, 4.0});
  EXPECT_EQ(d.n, 3);
  EXPECT_DOUBLE_EQ(*d.mean, 2.0);
  EXPECT_NEAR(*d.standard_error, 1.0 / std::sqrt(3.0), 1e-15);
  const report::PairedDifference one = report::paired_difference({1.0}, {0.5});
  EXPECT_EQ(one.n, 1);
  EXPECT_DOUBLE_EQ(*one.mean, 0.5);
  EXPECT_FALSE(one.standard_error.has_value());
  EXPECT_FALSE(report::paired_difference({std::nullopt}, {1.0}).mean.has_value());
}

TEST(Report, SubmissionReportMatchesScoreAndMarksDefects) {
  TempDir dir("report_sub");
  const fs::path ds = e2e_dataset();
  const PerturbedSubmission sub = perturbed_submission(dir.path());
  const fs::path out = dir / "report";
  CommandResult r = run_nsgraph(
      {"report", "--quiet", "--dataset", ds.string(), "--submission", sub.file.string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f :
       {"index.html", "report.js", "selftest.js", "report.css", "report.json", "data/summary.js", "data/tiles.js"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  EXPECT_NE(read_file(out / "index.html").find("report.js"), std::string::npos);
  EXPECT_EQ(read_file(out / "index.html").find("http"), std::string::npos) << "no network address in the page";

  // The scores are score's.
  r = run_nsgraph({"score", "--quiet", "--ground-truth", ds.string(), "--submission", sub.file.string(), "--out",
                   (dir / "score.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json score = read_json(dir / "score.json");
  const nlohmann::json summary = read_data_script(out / "data/summary.js");
  nlohmann::json marker = read_json(out / "report.json");
  // The marker is the summary and the list of every file the report wrote (it replaces only those).
  const nlohmann::json listed = marker["files"];
  marker.erase("files");
  EXPECT_EQ(summary, marker);
  std::vector<std::string> on_disk;
  for (const auto& e : fs::recursive_directory_iterator(out))
    if (e.is_regular_file()) on_disk.push_back(fs::relative(e.path(), out).generic_string());
  std::sort(on_disk.begin(), on_disk.end());
  EXPECT_EQ(listed.get<std::vector<std::string>>(), on_disk);
  EXPECT_EQ(summary["mode"], "submission");
  EXPECT_EQ(summary["split"], "test");
  EXPECT_EQ(summary["score"]["n_missing_predictions"], 1);
  // The headline metrics come first, named as the leaderboard and `score --format md` name
  // them; the summed Chamfer (m²) is none of them.
  ASSERT_EQ(summary["summary"].size(), static_cast<size_t>(metrics::kMetricCount));  // one row per metric
  EXPECT_EQ(summary["summary"][0]["metric"], "apls");
  EXPECT_EQ(summary["summary"][0]["label"], "APLS");
  EXPECT_EQ(summary["summary"][1]["label"], "APLS dir.");
  for (const auto& row : summary["summary"]) {
    const bool summed = row["metric"] == "chamfer_m2" || row["metric"] == "chamfer_px2";
    if (summed) {
      EXPECT_TRUE(row["label"].is_null()) << row;
    }
  }
  for (const auto& row : summary["summary"]) {
    const nlohmann::json& mean = score["aggregate"]["mean"][row["metric"].get<std::string>()];
    if (mean.is_null()) EXPECT_TRUE(row["mean"].is_null()) << row;
    else EXPECT_NEAR(row["mean"].get<double>(), mean.get<double>(), 1e-6) << row;
  }

  // One table row per test tile, in key order, with score's per-tile APLS.
  const nlohmann::json tiles = read_data_script(out / "data/tiles.js");
  ASSERT_EQ(tiles["keys"].size(), score["tiles"].size());
  size_t i = 0;
  for (const auto& [key, t] : score["tiles"].items()) {
    EXPECT_EQ(tiles["keys"][i], key);
    const nlohmann::json& apls = tiles["values"]["apls"][i];
    if (t["apls"].is_null()) EXPECT_TRUE(apls.is_null());
    else EXPECT_NEAR(apls.get<double>(), t["apls"].get<double>(), 1e-6);
    for (const char* layer : {"lidar", "rgb", "semantic", "vehicle", "coverage"})
      EXPECT_TRUE(fs::is_regular_file(out / "img" / (key + "." + layer + ".png"))) << key << " " << layer;
    EXPECT_TRUE(fs::is_regular_file(out / "data/tile" / (key + ".js"))) << key;
    ++i;
  }
  EXPECT_TRUE(fs::is_regular_file(out / "img/overview-boston-seaport.png"));
  ASSERT_EQ(summary["locations"].size(), 1u);
  EXPECT_EQ(summary["locations"][0]["regions"].size(), 2u);
  EXPECT_DOUBLE_EQ(summary["locations"][0]["buffer_m"].get<double>(), 25.6);

  // The reversed tile: every predicted edge matched with the wrong direction, nothing missed.
  const nlohmann::json rev = read_data_script(out / "data/tile" / (sub.reversed + ".js"));
  EXPECT_EQ(rev["marks"]["wrong_direction"], sub.reversed_edges);
  EXPECT_EQ(rev["marks"]["correct"], 0);
  EXPECT_EQ(rev["marks"]["missed_gt"], 0);
  EXPECT_EQ(rev["pred"]["edges"].size(), static_cast<size_t>(sub.reversed_edges));
  // The dropped tile: no prediction, every GT edge missed.
  const nlohmann::json drop = read_data_script(out / "data/tile" / (sub.dropped + ".js"));
  EXPECT_TRUE(drop["pred"].is_null());
  EXPECT_EQ(drop["marks"]["missed_gt"], drop["gt"]["edges"].size());
  EXPECT_EQ(drop["figures"]["missing_prediction"], 1.0);
}

TEST(Report, BaselineGivesPairedDifferences) {
  TempDir dir("report_base");
  const fs::path ds = e2e_dataset();
  const PerturbedSubmission sub = perturbed_submission(dir.path());
  const fs::path exact = exact_submission(dir.path());
  const fs::path out = dir / "report";
  const CommandResult r = run_nsgraph({"report", "--quiet", "--dataset", ds.string(), "--submission", exact.string(),
                                       "--baseline", sub.file.string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = read_json(out / "report.json");
  const nlohmann::json tiles = read_data_script(out / "data/tiles.js");
  for (const auto& row : summary["summary"]) {
    if (row["metric"] != "apls") continue;
    // The exact submission scores 1 wherever APLS is defined; the paired difference is
    // the mean of 1 − baseline over the tiles where both are defined.
    const auto& a = tiles["values"]["apls"];
    const auto& b = tiles["values"]["baseline.apls"];
    double sum = 0.0;
    int n = 0;
    for (size_t i = 0; i < a.size(); ++i)
      if (!a[i].is_null() && !b[i].is_null()) {
        EXPECT_DOUBLE_EQ(a[i].get<double>(), 1.0);
        sum += a[i].get<double>() - b[i].get<double>();
        ++n;
      }
    ASSERT_GT(n, 1);
    EXPECT_EQ(row["paired_n"], n);
    EXPECT_NEAR(row["paired_mean"].get<double>(), sum / n, 1e-6);
    EXPECT_GT(row["paired_mean"].get<double>(), 0.0);  // the baseline lost the dropped tile
    EXPECT_GT(row["paired_se"].get<double>(), 0.0);
    EXPECT_NEAR(row["difference"].get<double>(), row["mean"].get<double>() - row["baseline_mean"].get<double>(), 2e-6);
  }
  // Per tile, a sortable Δ column for every metric: submission − baseline, undefined unless both are.
  const auto& columns = summary["columns"];
  EXPECT_NE(std::find(columns.begin(), columns.end(), "delta.apls"), columns.end());
  EXPECT_NE(std::find(columns.begin(), columns.end(), "delta.chamfer_mean_m"), columns.end());
  int deltas = 0;
  for (const char* m : {"apls", "f1", "chamfer_mean_m"}) {
    const auto& a = tiles["values"][m];
    const auto& b = tiles["values"][std::string("baseline.") + m];
    const auto& d = tiles["values"][std::string("delta.") + m];
    ASSERT_EQ(d.size(), a.size()) << m;
    for (size_t i = 0; i < a.size(); ++i) {
      if (a[i].is_null() || b[i].is_null()) {
        EXPECT_TRUE(d[i].is_null()) << m << " " << i;
        continue;
      }
      EXPECT_NEAR(d[i].get<double>(), a[i].get<double>() - b[i].get<double>(), 2e-6) << m << " " << i;
      ++deltas;
    }
  }
  EXPECT_GT(deltas, 3);
  // The baseline's graph for the overlay: none where it dropped the tile, its reversed edges where it reversed them.
  const nlohmann::json dropped = read_data_script(out / "data/tile" / (sub.dropped + ".js"));
  EXPECT_TRUE(dropped.contains("base"));
  EXPECT_TRUE(dropped["base"].is_null());
  const nlohmann::json reversed = read_data_script(out / "data/tile" / (sub.reversed + ".js"));
  ASSERT_TRUE(reversed["base"].is_object());
  EXPECT_EQ(reversed["base"]["edges"].size(), static_cast<size_t>(sub.reversed_edges));
  EXPECT_EQ(reversed["figures"]["delta.apls"],
            reversed["metrics"]["apls"].get<double>() - reversed["baseline"]["apls"].get<double>())
      << reversed["figures"].dump();
}

// A rerun over an earlier report takes the layer images of tiles whose bytes (and this
// build) did not change, and the result is the same bytes as rendering them anew.
TEST(Report, RerunTakesTheImagesOfUnchangedTiles) {
  TempDir dir("report_reuse");
  const fs::path ds = e2e_dataset();
  const PerturbedSubmission sub = perturbed_submission(dir.path());
  const fs::path out = dir / "report";
  report::ReportOptions options;
  options.submission = sub.file;
  const report::ReportResult first = report::write_report(ds, out, options);
  ASSERT_GT(first.tiles, 1);
  EXPECT_EQ(first.images_reused, 0);
  const auto hashes = tree_hashes(out);
  const report::ReportResult second = report::write_report(ds, out, options);
  EXPECT_EQ(second.images_reused, second.tiles * 5);
  EXPECT_EQ(tree_hashes(out), hashes);

  // A tile whose fingerprint differs (its members or the build changed) is rendered again.
  nlohmann::json fingerprints = read_json(out / "img/fingerprints.json");
  const std::string key = fingerprints["tiles"].begin().key();
  fingerprints["tiles"][key] = std::string(64, '0');
  write_text(out / "img/fingerprints.json", fingerprints.dump());
  write_text(out / "img" / (key + ".lidar.png"), "stale");
  const report::ReportResult third = report::write_report(ds, out, options);
  EXPECT_EQ(third.images_reused, (third.tiles - 1) * 5);
  EXPECT_EQ(tree_hashes(out), hashes);

  // A missing image, or fingerprints that are not JSON: rendered, never trusted.
  fs::remove(out / "img" / (key + ".rgb.png"));
  EXPECT_EQ(report::write_report(ds, out, options).images_reused, (third.tiles - 1) * 5);
  write_text(out / "img/fingerprints.json", "{\"tiles\": [");
  EXPECT_EQ(report::write_report(ds, out, options).images_reused, 0);
  EXPECT_EQ(tree_hashes(out), hashes);
}

TEST(Report, DatasetOnlyHasStatsAndEveryTile) {
  TempDir dir("report_ds");
  const fs::path ds = e2e_dataset();
  const fs::path out = dir / "report";
  const CommandResult r = run_nsgraph({"report", "--quiet", "--dataset", ds.string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = read_json(out / "report.json");
  EXPECT_EQ(summary["mode"], "dataset");
  EXPECT_FALSE(summary.contains("score"));
  const nlohmann::json manifest = read_json(ds / "manifest.json");
  const int64_t all = manifest["counts"]["train"]["tiles"].get<int64_t>() +
                      manifest["counts"]["val"]["tiles"].get<int64_t>() +
                      manifest["counts"]["test"]["tiles"].get<int64_t>();
  EXPECT_EQ(summary["n_tiles"], all);
  EXPECT_EQ(summary["stats"]["test"]["tiles"], manifest["counts"]["test"]["tiles"]);
  const nlohmann::json tiles = read_data_script(out / "data/tiles.js");
  EXPECT_EQ(tiles["keys"].size(), static_cast<size_t>(all));
  EXPECT_FALSE(tiles["values"].contains("apls"));
  EXPECT_TRUE(tiles["values"].contains("coverage_lidar"));
  // Each tile view carries its ground truth's lane changes and junction nodes, as graph.json
  // has them (the overlays the tile view toggles).
  const io::Dataset dataset = io::Dataset::open(ds);
  size_t changes = 0, junctions = 0;
  dataset.for_each_tile("test", [&](const io::DatasetTile& tile) {
    const graph::TileGraph g = tile.graph();
    const nlohmann::json doc = read_data_script(out / "data" / "tile" / (tile.key + ".js"));
    EXPECT_EQ(doc["attributes"]["lane_changes"].size(), g.lane_changes.size()) << tile.key;
    if (doc["attributes"]["lane_changes"].size() != g.lane_changes.size()) return false;
    for (size_t k = 0; k < g.lane_changes.size(); ++k)
      EXPECT_EQ(doc["attributes"]["lane_changes"][k],
                nlohmann::json({g.lane_changes[k].source, g.lane_changes[k].target}));
    size_t tile_junctions = 0;
    for (const graph::TileNode& n : g.nodes) tile_junctions += n.junction != graph::Junction::kNone ? 1 : 0;
    EXPECT_EQ(doc["attributes"]["junctions"].size(), tile_junctions) << tile.key;
    changes += g.lane_changes.size();
    junctions += tile_junctions;
    return true;
  });
  EXPECT_GT(changes, 0u);
  EXPECT_GT(junctions, 0u);
}

TEST(Report, SameBytesAtAnyThreadCountAndRerunReplaces) {
  TempDir dir("report_det");
  const fs::path ds = e2e_dataset();
  const PerturbedSubmission sub = perturbed_submission(dir.path());
  for (const char* t : {"1", "2"}) {
    const CommandResult r = run_nsgraph({"report", "--quiet", "--dataset", ds.string(), "--submission",
                                         sub.file.string(), "--out", (dir / t).string(), "--threads", t});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  EXPECT_EQ(tree_hashes(dir / "1"), tree_hashes(dir / "2"));
  // A second run over an earlier report replaces the files it wrote; a file of the user's
  // in there is named and the run refused, the file kept.
  const std::vector<std::string> again = {"report",       "--quiet",         "--dataset", ds.string(),
                                          "--submission", sub.file.string(), "--out",     (dir / "1").string()};
  write_text(dir / "1" / "img" / "stale.txt", "x");
  CommandResult r = run_nsgraph(again);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("img/stale.txt"), std::string::npos) << r.err;
  EXPECT_EQ(read_file(dir / "1" / "img" / "stale.txt"), "x");
  fs::remove(dir / "1" / "img" / "stale.txt");
  r = run_nsgraph(again);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(tree_hashes(dir / "1"), tree_hashes(dir / "2"));
}

TEST(Report, BadInputsFailLikeScoreAndWriteNothing) {
  TempDir dir("report_bad");
  const fs::path ds = e2e_dataset();
  const fs::path out = dir / "report";
  // A submission with an edge to a node that does not exist: validate's problem, exit 1.
  write_text(
      dir / "bad.json",
      R"({"schema_version": "1", "tiles": {"boston-seaport-test-000000": {"nodes": [[1, 2]], "edges": [[0, 5]]}}})");
  CommandResult r = run_nsgraph(
      {"report", "--dataset", ds.string(), "--submission", (dir / "bad.json").string(), "--out", out.string()});
  const CommandResult s =
      run_nsgraph({"score", "--ground-truth", ds.string(), "--submission", (dir / "bad.json").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(s.exit_code, 1) << s.err;
  const std::string first_issue = s.err.substr(0, s.err.find('\n'));
  EXPECT_NE(r.err.find(first_issue), std::string::npos) << "report:\n" << r.err << "score:\n" << s.err;
  EXPECT_FALSE(fs::exists(out));

  // A dataset whose shard is gone: exit 2 naming the shard, nothing written.
  const fs::path broken = dir / "broken";
  fs::create_directories(broken);
  for (const auto& e : fs::directory_iterator(ds)) fs::create_directory_symlink(e.path(), broken / e.path().filename());
  fs::remove(broken / "shards");
  fs::create_directories(broken / "shards");
  for (const auto& e : fs::directory_iterator(ds / "shards"))
    if (e.path().filename() != "test-000001.tar") fs::create_symlink(e.path(), broken / "shards" / e.path().filename());
  const PerturbedSubmission sub = perturbed_submission(dir.path());
  r = run_nsgraph({"report", "--dataset", broken.string(), "--submission", sub.file.string(), "--out", out.string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("test-000001.tar"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();

  // A folder of other files is not overwritten; --baseline needs --submission.
  write_text(dir / "mine" / "notes.txt", "keep");
  r = run_nsgraph({"report", "--dataset", ds.string(), "--out", (dir / "mine").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(read_file(dir / "mine" / "notes.txt"), "keep");
  r = run_nsgraph({"report", "--dataset", ds.string(), "--baseline", sub.file.string(), "--out", out.string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--baseline"), std::string::npos) << r.err;
}

// The leaderboard keeps the reports whose receipts name the first one's ground truth and
// whose numbers still hash to their receipt; the others are named (exit 1) and listed.
TEST(Leaderboard, AcceptsMatchingReceiptsAndNamesTheRejected) {
  TempDir dir("leaderboard");
  const fs::path reports = leaderboard_reports(dir.path());
  const fs::path out = dir / "board";
  CommandResult r = run_nsgraph({"report", "--quiet", "--leaderboard", reports.string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"index.html", "leaderboard.js", "leaderboard.css", "leaderboard.json", "data/leaderboard.js"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  nlohmann::json board = read_json(out / "leaderboard.json");
  EXPECT_EQ(board["files"], nlohmann::json::parse(R"(["data/leaderboard.js", "index.html", "leaderboard.css",
                                                       "leaderboard.js", "leaderboard.json"])"));
  board.erase("files");  // the marker lists the page's files; the page's data does not
  EXPECT_EQ(read_data_script(out / "data/leaderboard.js"), board);
  ASSERT_EQ(board["entries"].size(), 3u);
  EXPECT_EQ(leaderboard_order(board, "apls"), (std::vector<std::string>{"exact", "perturbed", "empty"}));
  const nlohmann::json exact = read_json(reports / "exact.json");
  for (const auto& e : board["entries"])
    if (e["name"] == "exact") {
      EXPECT_EQ(e["values"]["apls"], exact["aggregate"]["mean"]["apls"]);
      EXPECT_EQ(e["submission_sha256"], exact["receipt"]["submission"]["sha256"]);
    }
  EXPECT_EQ(board["ground_truth"], exact["receipt"]["ground_truth"]);

  // Another ground truth (a file, not the dataset), a report edited after scoring, and a
  // JSON file that is no report: all three rejected by name, the page still written.
  fs::rename(reports / "exact.json", reports / "0-exact.json");  // stays the reference (first in name order)
  r = run_nsgraph({"score", "--quiet", "--ground-truth", exact_submission(dir.path()).string(), "--submission",
                   (dir / "perturbed.json").string(), "--format", "csv", "--out", (reports / "gt-file.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json edited = read_json(reports / "perturbed.json");
  edited["aggregate"]["mean"]["apls"] = 1.0;
  write_text(reports / "perturbed-edited.json", edited.dump());
  write_text(reports / "notes.json", R"({"comment": "not a report"})");
  r = run_nsgraph({"report", "--quiet", "--leaderboard", reports.string(), "--out", out.string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  board = read_json(out / "leaderboard.json");
  EXPECT_EQ(leaderboard_order(board, "apls"), (std::vector<std::string>{"0-exact", "perturbed", "empty"}));
  std::map<std::string, std::string> rejected;
  for (const auto& e : board["rejected"]) rejected[e["file"]] = e["reason"];
  ASSERT_EQ(rejected.size(), 3u) << board["rejected"].dump(1);
  EXPECT_NE(rejected["gt-file.json"].find("another ground truth"), std::string::npos) << rejected["gt-file.json"];
  EXPECT_NE(rejected["perturbed-edited.json"].find("changed after scoring"), std::string::npos);
  EXPECT_NE(rejected["notes.json"].find("receipt"), std::string::npos) << rejected["notes.json"];
  for (const char* name : {"gt-file.json", "perturbed-edited.json", "notes.json"})
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;

  // Not a folder of reports; a folder with none usable; --out holding other files.
  r = run_nsgraph({"report", "--leaderboard", (dir / "missing").string(), "--out", (dir / "b2").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  fs::create_directories(dir / "none");
  write_text(dir / "none" / "x.json", "{}");
  r = run_nsgraph({"report", "--leaderboard", (dir / "none").string(), "--out", (dir / "b3").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_FALSE(fs::exists(dir / "b3"));
  // --out the folder of reports itself (it used to replace it, every report deleted), or
  // a folder holding it: refused, nothing removed.
  const auto before = tree_hashes(reports);
  r = run_nsgraph({"report", "--leaderboard", reports.string(), "--out", reports.string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--leaderboard"), std::string::npos) << r.err;
  r = run_nsgraph({"report", "--leaderboard", reports.string(), "--out", dir.path().string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(tree_hashes(reports), before);
}

// An --out that holds an earlier leaderboard.json beside the user's other files was
// replaced whole; now only a page whose leaderboard.json lists every file is replaced.
TEST(Leaderboard, ReplacesOnlyAPageOfItsOwn) {
  TempDir dir("leaderboard-own");
  const fs::path reports = leaderboard_reports(dir.path());
  const fs::path out = dir / "board";
  const std::vector<std::string> args = {"report", "--quiet", "--leaderboard", reports.string(), "--out", out.string()};
  ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  ASSERT_EQ(run_nsgraph(args).exit_code, 0) << "a rerun replaces its own page";
  write_text(out / "my-notes.txt", "keep");
  CommandResult r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("my-notes.txt"), std::string::npos) << r.err;
  EXPECT_EQ(read_file(out / "my-notes.txt"), "keep");
  // A stranger's folder with a leaderboard.json (no listing) and other files: refused too.
  write_text(dir / "theirs" / "leaderboard.json", "{}");
  write_text(dir / "theirs" / "data.csv", "1,2");
  r = run_nsgraph({"report", "--quiet", "--leaderboard", reports.string(), "--out", (dir / "theirs").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(read_file(dir / "theirs" / "data.csv"), "1,2");
  // A report's --out holding a leaderboard is not a report of ours either.
  r = run_nsgraph({"report", "--quiet", "--dataset", e2e_dataset().string(), "--out", out.string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(read_file(out / "my-notes.txt"), "keep");
}

// Reports of a stranger with mistyped fields are rejected with their reason (exit 1 with
// the page written, or 2 when none is left), never an internal error.
TEST(Leaderboard, MistypedReportsAreRejectedByName) {
  TempDir dir("leaderboard-mistyped");
  const fs::path reports = leaderboard_reports(dir.path());
  const nlohmann::json good = read_json(reports / "exact.json");
  const std::vector<std::pair<std::string, std::function<void(nlohmann::json&)>>> cases = {
      {"receipt-number", [](nlohmann::json& d) { d["receipt"] = 7; }},
      {"no-ground-truth", [](nlohmann::json& d) { d["receipt"].erase("ground_truth"); }},
      {"metrics-version-number", [](nlohmann::json& d) { d["receipt"]["metrics_version"] = 3; }},
      {"commit-number", [](nlohmann::json& d) { d["receipt"]["toolkit"]["git_commit"] = 1; }},
      {"kind-array", [](nlohmann::json& d) { d["receipt"]["ground_truth"]["kind"] = nlohmann::json::array(); }},
      {"tiny-geo-step", [](nlohmann::json& d) { d["receipt"]["options"]["params"]["geo_step_px"] = 1e-9; }},
      {"limits-lifted", [](nlohmann::json& d) { d["receipt"]["limits"]["max_depth"] = 100000; }},
      {"n-tiles-string", [](nlohmann::json& d) { d["aggregate"]["n_tiles"] = "many"; }},
      {"digest-short", [](nlohmann::json& d) { d["receipt"]["results_sha256"] = "abc"; }},
  };
  for (const auto& [name, edit] : cases) {
    nlohmann::json doc = good;
    edit(doc);
    write_text(reports / ("z-" + name + ".json"), doc.dump());
  }
  const CommandResult r =
      run_nsgraph({"report", "--quiet", "--leaderboard", reports.string(), "--out", (dir / "board").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const nlohmann::json board = read_json(dir / "board" / "leaderboard.json");
  std::map<std::string, std::string> rejected;
  for (const auto& e : board["rejected"]) rejected[e["file"]] = e["reason"];
  for (const auto& [name, edit] : cases) {
    const std::string file = "z-" + name + ".json";
    ASSERT_TRUE(rejected.count(file)) << file;
    EXPECT_FALSE(rejected[file].empty());
  }
  EXPECT_NE(rejected["z-metrics-version-number.json"].find("/receipt/metrics_version"), std::string::npos)
      << rejected["z-metrics-version-number.json"];
  EXPECT_NE(rejected["z-tiny-geo-step.json"].find("geo_step_px"), std::string::npos);
}

}  // namespace
}  // namespace nsg::test
