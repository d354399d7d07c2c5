// A damaged manifest.json before every command that reads a dataset: each one reads it
// through the manifest's one reader (io/manifest.h), so each refuses with exit 2 naming the
// manifest and the JSON pointer of the field — never exit 3, never a signal.
#include <gtest/gtest.h>

#include <functional>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "test_support.h"

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace nsg::test {
namespace {

struct Damage {
  std::string name;
  std::string pointer;  // what the message must name
  std::function<void(json&)> edit;
};

const std::vector<Damage>& damages() {
  static const std::vector<Damage> kDamages = {
      {"bytes_a_string", "/shards/0/bytes", [](json& m) { m["shards"][0]["bytes"] = "12345"; }},
      {"sha256_a_number", "/shards/0/sha256", [](json& m) { m["shards"][0]["sha256"] = 12345; }},
      {"tiles_negative", "/shards/0/tiles", [](json& m) { m["shards"][0]["tiles"] = -1; }},
      {"size_px_9000", "/tile_format/size_px", [](json& m) { m["tile_format"]["size_px"] = 9000; }},
      {"file_dot_dot", "/shards/0/file", [](json& m) { m["shards"][0]["file"] = "../x"; }},
      {"file_absolute", "/shards/0/file", [](json& m) { m["shards"][0]["file"] = "/etc/passwd"; }},
      {"shards_not_an_array", "/shards",
       [](json& m) {
         m["shards"] = {{"name", "test-000000"}};
       }},
      {"tile_format_missing", "/tile_format", [](json& m) { m.erase("tile_format"); }},
  };
  return kDamages;
}

// A dataset of links to the e2e dataset's files but for its manifest, damaged.
fs::path damaged_dataset(const fs::path& dir, const Damage& d) {
  const fs::path source = e2e_dataset();
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(source))
    if (e.path().filename() != "manifest.json") fs::create_symlink(e.path(), dir / e.path().filename());
  json manifest = json::parse(read_file(source / "manifest.json"));
  d.edit(manifest);
  write_text(dir / "manifest.json", manifest.dump(1));
  return dir;
}

// A valid submission of one test tile (score reads the submission before the dataset).
fs::path one_tile_submission(const fs::path& dir) {
  const json manifest = json::parse(read_file(e2e_dataset() / "manifest.json"));
  std::string key;
  for (const json& s : manifest["shards"])
    if (s["split"] == "test" && key.empty()) key = s["first_key"].get<std::string>();
  const json doc = {{"schema_version", "1"},
                    {"tiles", {{key, {{"nodes", {{1.0, 1.0}, {20.0, 20.0}}}, {"edges", {{0, 1}}}}}}}};
  write_text(dir / "submission.json", doc.dump());
  return dir / "submission.json";
}

// Every command that reads a dataset, with what else it needs.
std::vector<std::pair<std::string, std::vector<std::string>>> commands(const fs::path& ds, const fs::path& out,
                                                                       const fs::path& submission) {
  const std::string d = ds.string(), o = out.string();
  const std::string model = (source_dir() / "samples/models/lanegraphnet-quickstart.onnx").string();
  return {
      {"stats", {"stats", d}},
      {"validate", {"validate", d}},
      {"score", {"score", "--ground-truth", d, "--submission", submission.string(), "--split", "test"}},
      {"preview", {"preview", d, "--out", o + "/preview"}},
      {"report", {"report", "--dataset", d, "--out", o + "/report"}},
      {"train", {"train", "--dataset", d, "--model", o + "/model.yml.gz"}},
      {"predict", {"predict", "--model", model, "--dataset", d, "--out", o + "/predicted.json"}},
      {"frames", {"frames", "--dataset", d, "--out", o + "/frames"}},
  };
}

TEST(HostileManifest, EveryCommandThatReadsADatasetExitsTwoNamingTheField) {
  TempDir tmp("hostile-manifest");
  const fs::path submission = one_tile_submission(tmp.path());
  for (const Damage& damage : damages()) {
    const fs::path ds = damaged_dataset(tmp / damage.name, damage);
    const std::string manifest = (ds / "manifest.json").string();
    for (const auto& [name, args] : commands(ds, tmp / (damage.name + "-out"), submission)) {
      SCOPED_TRACE(damage.name + " / " + name);
      std::vector<std::string> quiet = args;
      quiet.insert(quiet.begin() + 1, "--quiet");
      const CommandResult r = run_nsgraph(quiet);
      EXPECT_EQ(r.exit_code, 2) << r.err;
      EXPECT_NE(r.err.find(manifest), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(": " + damage.pointer + ": "), std::string::npos) << r.err;
      EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    }
  }
}

}  // namespace
}  // namespace nsg::test
