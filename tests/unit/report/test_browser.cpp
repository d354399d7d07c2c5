// The report in a real browser: Debian's chromium, headless, from file:// with no
// network. The page's self-test (#selftest=sort:<column>) sorts the per-tile table, opens
// a tile and the overview, and writes what it saw into <pre id="selftest">, which
// --dump-dom returns: rows in order, overlays present, errors caught by the page.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "nsg/metrics/measure.h"
#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/strings.h"
#include "nsg/preview/preview.h"
#include "report_fixture.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

bool have_chromium() { return run_program({"sh", "-c", "command -v chromium"}).exit_code == 0; }

// chromium headless on `url` with a fresh profile and nothing that reaches the network.
CommandResult chromium(const fs::path& profile, const std::vector<std::string>& args, const std::string& url) {
  std::vector<std::string> argv{"timeout",
                                "120",
                                "chromium",
                                "--headless",
                                "--no-sandbox",
                                "--disable-gpu",
                                "--disable-quic",
                                "--no-first-run",
                                "--disable-background-networking",
                                "--disable-component-update",
                                "--disable-sync",
                                "--disable-extensions",
                                "--user-data-dir=" + profile.string(),
                                "--virtual-time-budget=10000"};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.push_back(url);
  return run_program(argv);
}

// The self-test's JSON from the dumped DOM (text content: only & < > are escaped).
nlohmann::json selftest_of(const std::string& dom) {
  const size_t tag = dom.find("id=\"selftest\"");
  if (tag == std::string::npos) return nullptr;
  const size_t open = dom.find('>', tag) + 1, close = dom.find("</pre>", open);
  std::string text = dom.substr(open, close - open);
  for (const auto& [esc, ch] :
       std::vector<std::pair<std::string, std::string>>{{"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}})
    for (size_t p; (p = text.find(esc)) != std::string::npos;) text.replace(p, esc.size(), ch);
  if (text.empty()) return nullptr;
  return nlohmann::json::parse(text);
}

// Keys sorted by a column of data/tiles.js as the page must: ascending, undefined last,
// ties by key.
std::vector<std::string> expected_order(const nlohmann::json& tiles, const std::string& column) {
  std::vector<size_t> idx(tiles["keys"].size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  const nlohmann::json& v = tiles["values"][column];
  std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) {
    const std::string ka = tiles["keys"][a], kb = tiles["keys"][b];
    if (v[a].is_null() || v[b].is_null()) return v[a].is_null() == v[b].is_null() ? ka < kb : v[b].is_null();
    if (v[a].get<double>() != v[b].get<double>()) return v[a].get<double>() < v[b].get<double>();
    return ka < kb;
  });
  std::vector<std::string> keys;
  for (size_t i : idx) keys.push_back(tiles["keys"][i]);
  return keys;
}

std::string css_rgb(preview::Rgb c) { return strprintf("rgb(%d, %d, %d)", c.r, c.g, c.b); }

TEST(Browser, ReportLoadsSortsAndDrawsOverlays) {
  if (!have_chromium()) GTEST_SKIP() << "optional tool chromium not installed (apt-get install chromium)";
  TempDir dir("report_browser");
  const PerturbedSubmission sub = perturbed_submission(dir.path());
  const fs::path out = dir / "report";
  // The exact ground truth as the baseline: Δ columns and the baseline's overlay.
  CommandResult r =
      run_nsgraph({"report", "--quiet", "--dataset", e2e_dataset().string(), "--submission", sub.file.string(),
                   "--baseline", exact_submission(dir.path()).string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string url = "file://" + fs::absolute(out / "index.html").string();
  const nlohmann::json tiles = read_data_script(out / "data/tiles.js");

  r = chromium(dir / "profile1", {"--dump-dom"}, url + "#selftest=sort:apls");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json st = selftest_of(r.out);
  ASSERT_TRUE(st.is_object()) << "no self-test result in the DOM:\n" << r.out.substr(0, 2000) << "\n" << r.err;
  EXPECT_EQ(st["errors"], nlohmann::json::array()) << st.dump(1);
  EXPECT_EQ(st["rows"].get<std::vector<std::string>>(), expected_order(tiles, "apls"));
  EXPECT_EQ(st["summary_rows"], metrics::kMetricCount);  // one row per metric
  EXPECT_GT(st["tile"]["gt_paths"].get<int>(), 0) << st.dump(1);
  EXPECT_GT(st["tile"]["pred_paths"].get<int>(), 0) << st.dump(1);
  EXPECT_GT(st["tile"]["base_paths"].get<int>(), 0) << st.dump(1);
  // Every line over its casing, in the colours preview.h declares.
  EXPECT_EQ(
      st["tile"]["casing_paths"].get<int>(),
      st["tile"]["gt_paths"].get<int>() + st["tile"]["pred_paths"].get<int>() + st["tile"]["base_paths"].get<int>());
  EXPECT_EQ(st["tile"]["strokes"]["gt"], css_rgb(preview::kGtEdge)) << st.dump(1);
  EXPECT_EQ(st["tile"]["strokes"]["pred"], css_rgb(preview::kPredEdge)) << st.dump(1);
  EXPECT_EQ(st["tile"]["strokes"]["baseline"], css_rgb(preview::kBaselineEdge)) << st.dump(1);
  EXPECT_EQ(st["tile"]["strokes"]["casing"], css_rgb(preview::kOverlayCasing)) << st.dump(1);
  // The ground truth's lane changes and junctions: one path or ring each, behind two toggles.
  const nlohmann::json tile_doc =
      read_data_script(out / "data" / "tile" / (st["tile"]["key"].get<std::string>() + ".js"));
  EXPECT_EQ(st["tile"]["lane_change_paths"], tile_doc["attributes"]["lane_changes"].size()) << st.dump(1);
  EXPECT_EQ(st["tile"]["junction_rings"], tile_doc["attributes"]["junctions"].size()) << st.dump(1);
  EXPECT_EQ(st["tile"]["attribute_toggles"], 2);
  if (!tile_doc["attributes"]["lane_changes"].empty()) {
    EXPECT_EQ(st["tile"]["strokes"]["lane_change"], css_rgb(preview::kLaneChangeEdge)) << st.dump(1);
  }
  if (!tile_doc["attributes"]["junctions"].empty()) {
    EXPECT_EQ(st["tile"]["strokes"]["junction"], css_rgb(preview::kJunctionNode)) << st.dump(1);
  }
  // The table shows the Δ columns and hides the baseline's own values until chosen.
  const auto shown = st["table_columns"].get<std::vector<std::string>>();
  const nlohmann::json summary = read_data_script(out / "data/summary.js");
  EXPECT_EQ(st["chooser_boxes"], summary["columns"].size());
  EXPECT_NE(std::find(shown.begin(), shown.end(), "delta.apls"), shown.end());
  EXPECT_EQ(std::find(shown.begin(), shown.end(), "baseline.apls"), shown.end());
  EXPECT_NE(std::find(shown.begin(), shown.end(), "apls"), shown.end());
  // Each headline metric's Δ sits right beside it; the other metrics wait in the chooser.
  const auto at = [&](const std::string& c) { return std::find(shown.begin(), shown.end(), c) - shown.begin(); };
  EXPECT_EQ(at("delta.apls"), at("apls") + 1);
  EXPECT_EQ(at("delta.topo_f1"), at("topo_f1") + 1);
  EXPECT_EQ(std::find(shown.begin(), shown.end(), "chamfer_px2"), shown.end());
  EXPECT_EQ(std::find(shown.begin(), shown.end(), "delta.chamfer_px2"), shown.end());
  EXPECT_EQ(st["tile"]["layers"], 5);
  EXPECT_EQ(st["overview_tiles"], tiles["keys"].size());
  EXPECT_EQ(st["overview_regions"], 2);
  EXPECT_EQ(st["overview_buffers"], 2);

  // Sorted by a Δ column; the chooser's choice (#hide) shows exactly the columns not hidden.
  r = chromium(dir / "profile3", {"--dump-dom"}, url + "#hide=f1,delta.f1&selftest=table:delta.apls");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json by_delta = selftest_of(r.out);
  ASSERT_TRUE(by_delta.is_object()) << r.out.substr(0, 2000);
  EXPECT_EQ(by_delta["errors"], nlohmann::json::array()) << by_delta.dump(1);
  EXPECT_EQ(by_delta["rows"].get<std::vector<std::string>>(), expected_order(tiles, "delta.apls"));
  const auto chosen = by_delta["table_columns"].get<std::vector<std::string>>();
  EXPECT_EQ(chosen.size(), 2 + summary["columns"].size() - 2) << by_delta.dump(1);  // key, split; all but two
  EXPECT_EQ(std::find(chosen.begin(), chosen.end(), "delta.f1"), chosen.end());
  EXPECT_NE(std::find(chosen.begin(), chosen.end(), "baseline.f1"), chosen.end());

  // The tile view as a picture, on the semantic layer (where the former orange prediction
  // vanished on the road): not blank, and the prediction's own colour is on screen, drawn
  // over its casing (OverlayColours.StandOutOnEveryLayer checks the colours themselves).
  const std::string key = st["tile"]["key"];
  const fs::path png = dir / "tile.png";
  r = chromium(dir / "profile2", {"--screenshot=" + png.string(), "--window-size=1200,800", "--hide-scrollbars"},
               url + "#view=tile&layer=semantic&key=" + key);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::is_regular_file(png)) << r.err;
  const preview::Rgb p = preview::kPredEdge;
  r = run_program(
      {"/usr/bin/python3", "-c",
       "import sys; from PIL import Image; im = Image.open(sys.argv[1]).convert('RGB'); "
       "want = tuple(int(x) for x in sys.argv[2:5]); px = im.getdata(); "
       "print(len(im.getcolors(1 << 24)), sum(1 for c in px if max(abs(a - b) for a, b in zip(c, want)) <= 8), "
       "sum(1 for c in px if max(c) <= 8))",
       png.string(), std::to_string(p.r), std::to_string(p.g), std::to_string(p.b)});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int colours = 0, pred_px = 0, casing_px = 0;
  ASSERT_EQ(std::sscanf(r.out.c_str(), "%d %d %d", &colours, &pred_px, &casing_px), 3) << r.out;
  EXPECT_GT(colours, 50) << "distinct colours in the screenshot";
  EXPECT_GT(pred_px, 50) << "pixels of the prediction's colour";
  EXPECT_GT(casing_px, 50) << "pixels of the casing's colour";
}

// 20 000 tiles: data/tiles.js of the e2e report repeated under new keys (the table and the
// summary need no per-tile files). The first page of the table holds 100 rows in order and
// the summary paints within 2 s.
// A ladder dataset and a submission of its rung tiles: the summary draws one point per rung
// and main metric, and the rung table one row per metric; the tile view shows the layer of
// each rung side by side, and choosing rung 1 (predicted empty) puts its image and an empty
// prediction in the viewer, every ground-truth edge marked missed.
TEST(Browser, ReportDrawsTheCurvePerRung) {
  if (!have_chromium()) GTEST_SKIP() << "optional tool chromium not installed (apt-get install chromium)";
  TempDir dir("report_ladder");
  const fs::path ds = e2e_ladder_dataset();
  const fs::path out = dir / "report";
  CommandResult r = run_nsgraph({"report", "--quiet", "--dataset", ds.string(), "--submission",
                                 ladder_submission(dir.path()).string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = read_data_script(out / "data/summary.js");
  ASSERT_EQ(summary["rungs"].size(), 4u);
  r = chromium(dir / "profile", {"--dump-dom"},
               "file://" + fs::absolute(out / "index.html").string() + "#selftest=sort:apls");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json st = selftest_of(r.out);
  ASSERT_TRUE(st.is_object()) << r.out.substr(0, 2000);
  EXPECT_EQ(st["errors"], nlohmann::json::array()) << st.dump(1);
  // A point per rung and main metric where the mean is defined (rung 1 predicts nothing:
  // direction accuracy has no matched edge there).
  size_t points = 0;
  for (const auto& rung : summary["rungs"])
    for (const auto& metric : summary["main"]) points += rung["metrics"][metric.get<std::string>()]["mean"].is_number();
  EXPECT_GT(points, 3 * summary["main"].size());
  EXPECT_EQ(st["rung_points"], points) << st.dump(1);
  EXPECT_EQ(st["rung_rows"], metrics::kMetricCount) << st.dump(1);
  const std::string key = st["tile"]["key"];
  const nlohmann::json want_thumbs = {"img/" + key + "-r1.lidar.png", "img/" + key + "-r2.lidar.png",
                                      "img/" + key + "-r4.lidar.png", "img/" + key + ".lidar.png"};
  EXPECT_EQ(st["tile"]["rung_thumbs"], want_thumbs) << st.dump(1);
  const nlohmann::json& chosen = st["tile"]["rung_chosen"];
  EXPECT_EQ(chosen["rung"], "1") << st.dump(1);
  EXPECT_EQ(chosen["image"], "img/" + key + "-r1.lidar.png");
  EXPECT_EQ(chosen["pred_paths"], 0);
  EXPECT_EQ(chosen["missed_paths"], st["tile"]["gt_paths"]);
  EXPECT_GT(st["tile"]["gt_paths"].get<int>(), 0);
  EXPECT_EQ(chosen["selected"], 1);
}

TEST(Browser, TwentyThousandTilesStayUsable) {
  if (!have_chromium()) GTEST_SKIP() << "optional tool chromium not installed (apt-get install chromium)";
  TempDir dir("report_scale");
  const PerturbedSubmission sub = perturbed_submission(dir.path());
  const fs::path out = dir / "report";
  CommandResult r = run_nsgraph({"report", "--quiet", "--dataset", e2e_dataset().string(), "--submission",
                                 sub.file.string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json small = read_data_script(out / "data/tiles.js");
  constexpr size_t kTiles = 20000;
  const size_t n = small["keys"].size();
  nlohmann::json big = {{"keys", nlohmann::json::array()},
                        {"location", nlohmann::json::array()},
                        {"split", nlohmann::json::array()},
                        {"bounds_m", nlohmann::json::array()},
                        {"values", nlohmann::json::object()}};
  for (size_t i = 0; i < kTiles; ++i) {
    const size_t k = i % n;
    char key[64];
    std::snprintf(key, sizeof key, "boston-seaport-test-%06zu", i);
    big["keys"].push_back(key);
    big["location"].push_back(small["location"][k]);
    big["split"].push_back("test");
    const double x = 2000.0 + 60.0 * static_cast<double>(i % 150), y = 2000.0 + 60.0 * static_cast<double>(i / 150);
    big["bounds_m"].push_back({x, y, x + 51.2, y + 51.2});
    for (const auto& [col, vals] : small["values"].items()) big["values"][col].push_back(vals[k]);
  }
  // Written as the report writes its data (no quote or backslash in this text to escape).
  write_text(out / "data/tiles.js", "NSG.receive(\"tiles\", JSON.parse('" + big.dump() + "'));\n");
  nlohmann::json summary = read_data_script(out / "data/summary.js");
  summary["n_tiles"] = kTiles;
  write_text(out / "data/summary.js",
             "NSG.receive(\"summary\", " + summary.dump() + ");\n");  // an object literal works too

  r = chromium(dir / "profile", {"--dump-dom"},
               "file://" + fs::absolute(out / "index.html").string() + "#selftest=table:apls:desc");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json st = selftest_of(r.out);
  ASSERT_TRUE(st.is_object()) << r.out.substr(0, 2000) << "\n" << r.err;
  EXPECT_EQ(st["errors"], nlohmann::json::array()) << st.dump(1);
  ASSERT_EQ(st["rows"].size(), 100u) << "one page of the table";
  // Descending APLS: the first rows carry the largest value.
  const nlohmann::json& apls = big["values"]["apls"];
  double best = -1.0;
  for (const auto& v : apls)
    if (!v.is_null()) best = std::max(best, v.get<double>());
  const auto first = std::find(big["keys"].begin(), big["keys"].end(), st["rows"][0]);
  ASSERT_NE(first, big["keys"].end());
  EXPECT_EQ(apls[first - big["keys"].begin()].get<double>(), best);
  ASSERT_FALSE(st["first_contentful_paint_ms"].is_null()) << st.dump(1);
  std::printf(
      "20000 tiles: first contentful paint %.0f ms, first render %.0f ms, tiles loaded %.0f ms, table %.0f ms\n",
      st["first_contentful_paint_ms"].get<double>(), st["first_render_ms"].get<double>(),
      st["tiles_loaded_ms"].get<double>(), st["table_ms"].get<double>());
  EXPECT_LT(st["first_contentful_paint_ms"].get<double>(), 2000.0) << st.dump(1);
}

// The leaderboard page in Chromium from file://: sorted by a metric's better direction
// (APLS descending, Chamfer ascending, undefined last) or as asked, no script error.
TEST(Browser, LeaderboardLoadsAndSorts) {
  if (!have_chromium()) GTEST_SKIP() << "optional tool chromium not installed (apt-get install chromium)";
  TempDir dir("leaderboard_browser");
  const fs::path reports = leaderboard_reports(dir.path());
  const fs::path out = dir / "board";
  CommandResult r = run_nsgraph({"report", "--quiet", "--leaderboard", reports.string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json board = read_json(out / "leaderboard.json");
  const std::string url = "file://" + fs::absolute(out / "index.html").string();
  int profile = 0;
  for (const auto& [column, dir_arg] :
       std::vector<std::pair<std::string, std::string>>{{"apls", ""}, {"chamfer_mean_m", ""}, {"f1", "asc"}}) {
    const std::string spec = column + (dir_arg.empty() ? "" : ":" + dir_arg);
    r = chromium(dir / ("profile" + std::to_string(++profile)), {"--dump-dom"}, url + "#selftest=sort:" + spec);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json st = selftest_of(r.out);
    ASSERT_TRUE(st.is_object()) << "no self-test result in the DOM:\n" << r.out.substr(0, 2000) << "\n" << r.err;
    EXPECT_EQ(st["errors"], nlohmann::json::array()) << st.dump(1);
    EXPECT_EQ(st["sorted_by"], column);
    EXPECT_EQ(st["rows"].get<std::vector<std::string>>(), leaderboard_order(board, column, dir_arg)) << spec;
    EXPECT_EQ(st["columns"], 2 + board["columns"].size() + 4);
    EXPECT_EQ(st["rejected"], 0);
  }
}

}  // namespace
}  // namespace nsg::test
