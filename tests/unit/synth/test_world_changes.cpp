// Map changes (config `changes`, nsg/synth/changes.h) on the tiny world: the prior is the
// world as built, byte for byte; each edit is in the current map and only there, every other
// record keeps its token; the sensors see the changed world (paint, barriers, traffic); a
// release made with changes carries both maps and changes.json, and one without is
// byte-identical to a release without the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/rng.h"
#include "nsg/core/sha256.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/map_expansion.h"
#include "nsg/synth/changes.h"
#include "nsg/synth/config.h"
#include "nsg/synth/lidar_sim.h"
#include "nsg/synth/traffic.h"
#include "nsg/validate/documents.h"
#include "nsg/validate/schema.h"
#include "test_support.h"

namespace nsg::synth {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path& tiny_config_path() {
  static const fs::path p = test::source_dir() / "samples" / "synth" / "tiny.json";
  return p;
}

// tiny.json over two capture days, one edit of each kind from day 1 on.
const std::vector<std::string>& change_settings() {
  static const std::vector<std::string> s = {
      "scenes.count=4",         "scenes.capture_days=2",      "changes.from_day=1",
      "changes.lanes_closed=1", "changes.turns_removed=1",    "changes.crossings_added=1",
      "changes.turns_added=1",  "changes.dividers_retyped=1", "scenes.samples_per_scene=3"};
  return s;
}
SynthConfig changed_config() { return resolve_synth_config(tiny_config_path(), change_settings()); }
const ChangedWorld& changed() {
  static const ChangedWorld w = build_changed_world(changed_config(), 7);
  return w;
}

std::set<std::string> tokens(const json& map, const char* layer) {
  std::set<std::string> out;
  for (const json& r : map.at(layer)) out.insert(r.at("token").get<std::string>());
  return out;
}
std::set<std::string> keys(const json& object) {
  std::set<std::string> out;
  for (const auto& [k, v] : object.items()) out.insert(k);
  return out;
}
std::set<std::string> minus(std::set<std::string> a, const std::vector<std::string>& b) {
  for (const std::string& t : b) a.erase(t);
  return a;
}
const MapEdit& edit_of(const char* kind) {
  for (const MapEdit& e : changed().edits)
    if (e.kind == kind) return e;
  throw std::runtime_error(std::string("no edit ") + kind);
}
double distance_m(const std::array<double, 2>& a, double x, double y) { return std::hypot(a[0] - x, a[1] - y); }
// Ground samples of `material` every `step_m` within ±half_m of `at` in world `w`.
int material_near(const World& w, const std::array<double, 2>& at, double half_m, double step_m,
                  GroundMaterial material) {
  int n = 0;
  for (double dx = -half_m; dx <= half_m; dx += step_m)
    for (double dy = -half_m; dy <= half_m; dy += step_m)
      n += w.ground->material(at[0] + dx, at[1] + dy) == material ? 1 : 0;
  return n;
}

TEST(WorldChanges, ThePriorIsTheWorldAsBuilt) {
  const World built = build_world(changed_config(), 7);
  EXPECT_EQ(changed().prior.map_json, built.map_json);
  ASSERT_EQ(changed().prior.lanes.size(), built.lanes.size());
  EXPECT_EQ(changed().prior.buildings.size(), built.buildings.size());
  const GroundRaster& a = *changed().prior.ground;
  const GroundRaster& b = *built.ground;
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  size_t differ = 0;
  for (int row = 0; row < a.height(); row += 2)
    for (int col = 0; col < a.width(); col += 2) {
      const double x = a.x0() + (col + 0.5) * a.resolution(), y = a.y0() + (row + 0.5) * a.resolution();
      differ += a.material(x, y) != b.material(x, y) ? 1 : 0;
    }
  EXPECT_EQ(differ, 0u);
}

TEST(WorldChanges, EachEditIsInTheCurrentMapAndOnlyThere) {
  const json prior = json::parse(changed().prior.map_json), current = json::parse(changed().current.map_json);
  ASSERT_EQ(changed().edits.size(), kMapEditKinds.size());
  for (size_t k = 0; k < kMapEditKinds.size(); ++k) EXPECT_EQ(changed().edits[k].kind, kMapEditKinds[k]);

  std::vector<std::string> removed, added;
  for (const MapEdit& e : changed().edits) {
    removed.insert(removed.end(), e.removed.begin(), e.removed.end());
    added.insert(added.end(), e.added.begin(), e.added.end());
  }
  const MapEdit& closed = edit_of("lane_closed");
  EXPECT_GE(closed.removed.size(), 2u);  // the lane and the connectors into and out of it
  EXPECT_TRUE(tokens(prior, "lane").count(closed.removed.front()));
  EXPECT_EQ(edit_of("turn_removed").removed.size(), 1u);
  EXPECT_TRUE(tokens(prior, "lane_connector").count(edit_of("turn_removed").removed.front()));
  ASSERT_EQ(edit_of("crossing_added").added.size(), 1u);
  ASSERT_EQ(edit_of("turn_added").added.size(), 1u);
  EXPECT_FALSE(tokens(prior, "lane_connector").count(edit_of("turn_added").added.front()));
  // The retyped divider and its two lanes: dashed in the prior, solid in the current map.
  const std::vector<std::string>& retyped = edit_of("divider_retyped").retyped;
  ASSERT_EQ(retyped.size(), 3u);
  const auto segment_types = [&](const json& map, const char* layer, const std::string& token) {
    std::multiset<std::string> types;
    for (const json& r : map[layer])
      if (r["token"] == token)
        for (const char* side : {"lane_divider_segments", "left_lane_divider_segments", "right_lane_divider_segments"})
          if (r.contains(side))
            for (const json& seg : r[side]) types.insert(seg["segment_type"].get<std::string>());
    return types;
  };
  const auto dashed = segment_types(prior, "lane_divider", retyped[0]);
  ASSERT_FALSE(dashed.empty());
  EXPECT_EQ(dashed.count("SINGLE_DASHED_WHITE"), dashed.size());
  EXPECT_EQ(segment_types(current, "lane_divider", retyped[0]).count("SINGLE_SOLID_WHITE"), dashed.size());
  for (size_t k = 1; k < 3; ++k) {
    EXPECT_GE(segment_types(prior, "lane", retyped[k]).count("SINGLE_DASHED_WHITE"), 1u);
    EXPECT_EQ(segment_types(current, "lane", retyped[k]).count("SINGLE_DASHED_WHITE"), 0u);
    EXPECT_EQ(segment_types(current, "lane", retyped[k]).size(), segment_types(prior, "lane", retyped[k]).size());
  }

  // Lanes and connectors: the prior's less the removed; crossings: the prior's plus the added.
  EXPECT_EQ(tokens(current, "lane"), minus(tokens(prior, "lane"), removed));
  std::set<std::string> connectors = minus(tokens(prior, "lane_connector"), removed);
  connectors.insert(added.begin(), added.end());
  EXPECT_EQ(tokens(current, "lane_connector"), minus(connectors, edit_of("crossing_added").added));
  std::set<std::string> arclines = minus(keys(prior["arcline_path_3"]), removed);
  arclines.insert(edit_of("turn_added").added.front());
  EXPECT_EQ(keys(current["arcline_path_3"]), arclines);
  EXPECT_EQ(keys(current["connectivity"]), keys(current["arcline_path_3"]));
  std::set<std::string> crossings = tokens(prior, "ped_crossing");
  crossings.insert(edit_of("crossing_added").added.front());
  EXPECT_EQ(tokens(current, "ped_crossing"), crossings);
  // No connectivity list names a removed token.
  const std::set<std::string> gone(removed.begin(), removed.end());
  for (const auto& [token, links] : current["connectivity"].items())
    for (const char* way : {"incoming", "outgoing"})
      for (const json& t : links[way]) EXPECT_FALSE(gone.count(t.get<std::string>())) << token;
  // Every other layer is the prior's, record for record.
  EXPECT_EQ(tokens(current, "lane_divider"), tokens(prior, "lane_divider"));
  for (const char* layer : {"road_segment", "road_block", "road_divider", "stop_line", "walkway", "traffic_light",
                            "drivable_area", "carpark_area"})
    EXPECT_EQ(current[layer], prior[layer]) << layer;
  // The changed world's lanes are the current map's, their links in range.
  std::set<std::string> lane_tokens;
  for (const LaneInfo& lane : changed().current.lanes) {
    lane_tokens.insert(lane.token);
    for (const std::vector<int>* links : {&lane.outgoing, &lane.incoming})
      for (const int j : *links) EXPECT_LT(static_cast<size_t>(j), changed().current.lanes.size());
  }
  EXPECT_EQ(lane_tokens, keys(current["arcline_path_3"]));
  // Atomic: each edit far from the others.
  for (size_t i = 0; i < changed().edits.size(); ++i)
    for (size_t j = i + 1; j < changed().edits.size(); ++j)
      EXPECT_GE(distance_m(changed().edits[i].at_m, changed().edits[j].at_m[0], changed().edits[j].at_m[1]),
                kMinEditSpacingM);
}

TEST(WorldChanges, TheSensorsSeeTheChangedWorld) {
  // The crossing: stripes in the current ground where the prior has none, and the LiDAR of a
  // sensor above the road next to it sees them (crosswalk paint is the brightest ground).
  const std::array<double, 2> at = edit_of("crossing_added").at_m;
  const auto stripes = [&](const World& w) { return material_near(w, at, 2.0, 0.1, GroundMaterial::kCrosswalkPaint); };
  EXPECT_EQ(stripes(changed().prior), 0);
  EXPECT_GT(stripes(changed().current), 200);
  const auto bright_returns = [&](const World& w) {
    // 6 m off (the nearest ground return of a 1.84 m-high HDL-32E is 3.1 m away), axes as the map's.
    geometry::Rigid3 sensor;
    sensor.translation = {at[0] + 6.0, at[1], 1.84};
    LidarSimOptions lo;
    Rng rng(7, 1);
    const std::vector<float> pts = simulate_lidar_sweep(w.snapshot({}), sensor, lo, rng);
    int n = 0;
    for (size_t i = 0; i + 4 < pts.size(); i += 5)
      if (distance_m(at, pts[i] + sensor.translation.x(), pts[i + 1] + sensor.translation.y()) < 2.0 &&
          pts[i + 3] >= 0.6 * lidar_ground_intensity(GroundMaterial::kCrosswalkPaint))
        ++n;
    return n;
  };
  EXPECT_GT(bright_returns(changed().current), 2 * bright_returns(changed().prior) + 20);

  // The retyped divider: its gaps painted, so more of its line is paint in the current world.
  const std::array<double, 2> divider_at = edit_of("divider_retyped").at_m;
  const auto paint_near = [&](const World& w) {
    return material_near(w, divider_at, 6.0, 0.05, GroundMaterial::kPaintWhite);
  };
  EXPECT_GT(paint_near(changed().current), paint_near(changed().prior) * 5 / 4);

  // The closed lane: barriers along it in the current world only.
  const std::array<double, 2> lane_at = edit_of("lane_closed").at_m;
  const auto barriers_near = [&](const World& w) {
    return std::count_if(w.buildings.begin(), w.buildings.end(),
                         [&](const SceneBox& b) { return distance_m(lane_at, b.center_m.x(), b.center_m.y()) < 4.0; });
  };
  EXPECT_EQ(barriers_near(changed().prior), 0);
  EXPECT_GE(barriers_near(changed().current), 1);

  // Traffic: routes on the changed world never drive a removed lane or connector.
  std::set<std::string> gone;
  for (const MapEdit& e : changed().edits) gone.insert(e.removed.begin(), e.removed.end());
  const World& w = changed().current;
  // ... and do drive the added turn.
  Rng rng(7, 2);
  int added_turn_driven = 0;
  for (size_t start = 0; start < w.lanes.size(); ++start)
    for (int k = 0; k < 5; ++k)
      for (const int lane : random_route(w, static_cast<int>(start), 300.0, rng).lanes) {
        EXPECT_FALSE(gone.count(w.lanes[static_cast<size_t>(lane)].token));
        added_turn_driven += w.lanes[static_cast<size_t>(lane)].token == edit_of("turn_added").added.front() ? 1 : 0;
      }
  EXPECT_GT(added_turn_driven, 0);
}

// Every file of a folder with its sha256.
std::map<std::string, std::string> tree_digests(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) out[fs::relative(e.path(), root).string()] = sha256_file(e.path());
  return out;
}

fs::path synth(const test::TempDir& dir, const std::string& name, const std::vector<std::string>& settings) {
  std::vector<std::string> args = {"synth",  "--quiet", "--config", tiny_config_path().string(),
                                   "--seed", "7",       "--out",    (dir / name).string()};
  for (const std::string& s : settings) args.insert(args.end(), {"--set", s});
  const test::CommandResult r = test::run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return dir / name;
}

TEST(WorldChanges, AReleaseCarriesBothMapsAndTheEditsAndScenesFromTheDateSeeTheChange) {
  test::TempDir dir("synth-changes");
  const fs::path root = synth(dir, "changed", change_settings());
  const json doc = json::parse(read_file(root / "changes.json"));
  const MapChanges typed = read_map_changes(root / "changes.json");  // the one reader takes what synth wrote
  EXPECT_EQ(typed.edits.size(), kMapEditKinds.size());
  EXPECT_EQ(doc["kind"], "nsgraph-synth-changes");
  ASSERT_EQ(doc["edits"].size(), kMapEditKinds.size());
  EXPECT_EQ(doc["edits"][3]["retyped"], json(edit_of("divider_retyped").retyped));
  EXPECT_EQ(doc["edits"][0]["removed"], json(edit_of("lane_closed").removed));
  EXPECT_EQ(read_file(root / doc["prior_map"].get<std::string>()), changed().prior.map_json);
  EXPECT_EQ(read_file(root / doc["current_map"].get<std::string>()), changed().current.map_json);
  // The devkit-style reader loads the current map (the release's maps/expansion/) whole.
  const nuscenes::MapExpansion map = nuscenes::load_map_expansion(root, "boston-seaport");
  EXPECT_TRUE(map.issues().empty());
  // The date: the first scene of day 1 (scenes 2 and 3 of four over two days).
  const nuscenes::Database db = nuscenes::Database::load(root, "v1.0-mini");
  ASSERT_EQ(db.scene.size(), 4u);
  EXPECT_EQ(doc["date"], db.log[db.scene[2].log].date_captured);
  EXPECT_LT(db.log[db.scene[1].log].date_captured, doc["date"].get<std::string>());

  // Scenes before the date are the world without changes: their files are the same bytes as
  // in a release without the key (the scenes from the date on differ).
  const fs::path plain = synth(dir, "plain", {"scenes.count=4", "scenes.capture_days=2", "scenes.samples_per_scene=3"});
  const auto a = tree_digests(plain), b = tree_digests(root);
  int same_before = 0, differ_after = 0;
  for (const auto& sd : db.sample_data) {
    if (sd.fileformat != "pcd") continue;
    const bool after = db.log[db.scene[db.sample[sd.sample].scene].log].date_captured >= doc["date"].get<std::string>();
    const bool same = a.at(sd.filename) == b.at(sd.filename);
    if (!after) {
      EXPECT_TRUE(same) << sd.filename;
      same_before += same ? 1 : 0;
    } else {
      differ_after += same ? 0 : 1;
    }
  }
  EXPECT_GT(same_before, 0);
  EXPECT_GT(differ_after, 0);  // the barriers and the paint are in the later sweeps

  // Without an edit the key changes nothing: the same bytes as a release without it.
  const fs::path none = synth(
      dir, "none", {"scenes.count=4", "scenes.capture_days=2", "scenes.samples_per_scene=3", "changes.from_day=1"});
  EXPECT_EQ(tree_digests(none), a);
  EXPECT_FALSE(fs::exists(none / "changes.json"));
}

TEST(WorldChanges, ChangesJsonRoundTripsItsSchemaAndRefusesWhatTheFormatDoesNot) {
  test::TempDir dir("synth-changes-doc");
  MapChanges c;
  c.location = "boston-seaport";
  c.from_day = 9;
  c.date = "2018-08-01";
  c.prior_map = "maps/prior/expansion/boston-seaport.json";
  c.current_map = "maps/expansion/boston-seaport.json";
  c.edits = changed().edits;
  const std::string text = map_changes_text(c);
  test::write_text(dir / "changes.json", text);
  const MapChanges back = read_map_changes(dir / "changes.json");
  EXPECT_EQ(map_changes_text(back), text);
  ASSERT_EQ(back.edits.size(), c.edits.size());
  EXPECT_EQ(back.edits[3].retyped, c.edits[3].retyped);
  const Issues issues = validate::validate_against_schema(validate::schema_path("synth-changes"), json::parse(text),
                                                          "changes.json", "synth-changes.schema");
  EXPECT_TRUE(issues.empty()) << issues.size();
  // Hostile files: each refused by name (ParseError, the JSON pointer), never read past its bound.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"\"prior_map\": \"maps/prior/expansion/boston-seaport.json\"", "\"prior_map\": \"../../etc/passwd\""},
      {"\"from_day\": 9", "\"from_day\": \"9\""},
      {"\"kind\": \"lane_closed\"", "\"kind\": \"lane_teleported\""},
      {"\"schema_version\": \"1\"", "\"schema_version\": \"1\", \"extra\": 1"},
      {"\"date\": \"2018-08-01\"", "\"date\": \"yesterday\""}};
  for (const auto& [from, to] : bad) {
    std::string t = text;
    const size_t at = t.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    test::write_text(dir / "bad.json", t);
    EXPECT_THROW(read_map_changes(dir / "bad.json"), ParseError) << to;
  }
  test::write_text(dir / "deep.json", std::string(100, '[') + std::string(100, ']'));
  EXPECT_THROW(read_map_changes(dir / "deep.json"), ParseError);
  fs::create_symlink("/dev/zero", dir / "zero.json");
  EXPECT_THROW(read_map_changes(dir / "zero.json"), ParseError);
}

TEST(WorldChanges, MoreEditsThanTheWorldHoldsOrADayWithoutScenesAreRefusedByName) {
  SynthConfig c = changed_config();
  c.changes.lanes_closed = 100;
  try {
    build_changed_world(c, 7);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.record(), "changes.lanes_closed");
    EXPECT_NE(e.expected().find("at most"), std::string::npos) << e.what();
  }
  const test::CommandResult r =
      test::run_nsgraph({"synth", "--quiet", "--config", tiny_config_path().string(), "--out", "/nonexistent/x",
                         "--set", "changes.crossings_added=1", "--set", "changes.from_day=1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("changes.from_day"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nsg::synth
