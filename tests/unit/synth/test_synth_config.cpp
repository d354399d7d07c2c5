// The world config's declarations: every key read from a file and from --set with its
// range checked once, errors naming the key and its source, the listing and the schema
// generated from the declarations, every sample world valid.
#include <gtest/gtest.h>

#include <set>

#include "nsg/core/files.h"
#include "nsg/synth/config.h"
#include "nsg/validate/schema.h"
#include "options_test.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TEST(SynthConfig, EveryKeyRefusesABadValueNamingTheKeyAndItsSource) {
  const std::vector<options::Spec> specs = synth::synth_option_table().specs();
  ASSERT_GT(specs.size(), 40u);
  expect_every_key_refused_naming_it(
      specs,
      [](const fs::path& file, const std::vector<std::string>& settings) {
        synth::resolve_synth_config(file, settings);
      },
      "synth");
  // Through the binary, exit code included.
  const CommandResult r = run_nsgraph({"synth", "--print-config", "--set", "camera.jpeg_quality=0"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--set: camera.jpeg_quality: an integer in [1, 100] (got 0)"), std::string::npos) << r.err;
}

TEST(SynthConfig, MessagesNameTheKeyTheSourceAndTheCloseKey) {
  TempDir dir("synth-config");
  write_text(dir / "typo.json", R"({"city": {"blokcs_x": 3}})");
  CommandResult r = run_nsgraph({"synth", "--print-config", "--config", (dir / "typo.json").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find((dir / "typo.json").string() + ": city.blokcs_x"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("did you mean 'city.blocks_x'"), std::string::npos) << r.err;
  // A check across keys blames the key and the source that set it.
  r = run_nsgraph({"synth", "--print-config", "--config", (source_dir() / "samples/synth/tiny.json").string(), "--set",
                   "lidar.roof_points=8000"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--set: lidar.roof_points: an integer in [0, points_per_sweep)"), std::string::npos) << r.err;
  write_text(dir / "small.json", R"({"map_size_m": [200, 200], "city": {"blocks_x": 4}})");
  r = run_nsgraph({"synth", "--print-config", "--config", (dir / "small.json").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find((dir / "small.json").string() + ": map_size_m: a map large enough"), std::string::npos) << r.err;
  // --set and --seed over the file, in that order.
  r = run_nsgraph({"synth", "--print-config", "--config", (source_dir() / "samples/synth/tiny.json").string(), "--set",
                   "scenes.count=3", "--seed", "11"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json printed = json::parse(r.out);
  EXPECT_EQ(printed["scenes"]["count"], 3);
  EXPECT_EQ(printed["seed"], 11);
  EXPECT_EQ(printed["camera"]["channels"], json({"CAM_FRONT", "CAM_BACK"}));
}

TEST(SynthConfig, ListOptionsCoversEveryKeyOfTheResolvedConfig) { expect_listed_keys_are_the_config_leaves("synth"); }

TEST(SynthConfig, SchemaIsTheDeclarationsAndEverySampleWorldFitsIt) {
  const CommandResult schema = run_nsgraph({"synth", "--list-options", "--format", "schema"});
  ASSERT_EQ(schema.exit_code, 0) << schema.err;
  const fs::path schema_file = source_dir() / "schemas/v1/synth-config.schema.json";
  EXPECT_EQ(json::parse(schema.out), json::parse(read_file(schema_file)))
      << "make regen regenerates it: nsgraph synth --list-options --format schema > "
         "schemas/v1/synth-config.schema.json";
  const validate::SchemaValidator validator(schema_file);
  std::vector<fs::path> worlds;
  for (const fs::path& dir : {source_dir() / "samples/synth", data_dir() / "synth"})
    for (const fs::directory_entry& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".json") worlds.push_back(e.path());
  ASSERT_GE(worlds.size(), 5u);
  for (const fs::path& world : worlds) {
    EXPECT_NO_THROW(synth::SynthConfig::from_file(world).validate()) << world;
    const Issues issues = validator.validate(json::parse(read_file(world)), world.string(), "synth-config.schema");
    EXPECT_TRUE(issues.empty()) << issues.format();
  }
  // The defaults are a world of their own.
  EXPECT_NO_THROW(synth::SynthConfig{}.validate());
}

}  // namespace
}  // namespace nsg::test
