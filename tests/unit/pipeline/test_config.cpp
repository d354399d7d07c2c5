// The generate config's declarations: every key read from a file and from --set with its
// range checked once, errors naming the key and its source, and the listings, schema,
// sample config and docs generated from (or checked against) the declarations.
#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <set>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/options.h"
#include "nsg/io/dataset.h"
#include "nsg/io/raster.h"
#include "nsg/io/tile_members.h"
#include "nsg/pipeline/config.h"
#include "options_test.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

namespace nsg::test {
namespace {

// Through the command line's own resolver (the CLI adds only argument parsing, checked in
// MessagesNameTheFileKeyAndFlag): fast enough for every key.
TEST(GenerateConfig, EveryKeyRefusesABadValueNamingTheKeyAndItsSource) {
  const std::vector<options::Spec> specs = pipeline::generate_option_table().specs();
  ASSERT_GT(specs.size(), 40u);
  expect_every_key_refused_naming_it(
      specs,
      [](const fs::path& file, const std::vector<std::string>& settings) {
        pipeline::resolve_generate_config(file, settings);
      },
      "generate");
  // And two of them through the binary, exit code included.
  const CommandResult r = run_nsgraph({"generate", "--print-config", "--set", "camera.occlusion_window_px=600"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--set: camera.occlusion_window_px: an integer in [0, 512] (px) (got 600)"), std::string::npos)
      << r.err;
}

TEST(GenerateConfig, MessagesNameTheFileKeyAndFlag) {
  // The two messages that used to name keys of no config file.
  CommandResult r = run_nsgraph({"generate", "--print-config", "--set", "lidar.channel="});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--set: lidar.channel: a non-empty string"), std::string::npos) << r.err;
  r = run_nsgraph({"generate", "--print-config", "--set", "vehicles.score_threshold=2"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--set: vehicles.score_threshold: a number in [0, 1] (got 2)"), std::string::npos) << r.err;
  // A flag names itself and its key.
  r = run_nsgraph({"generate", "--print-config", "--score-threshold", "1.5"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--score-threshold: vehicles.score_threshold"), std::string::npos) << r.err;
  // Unknown keys suggest the close one.
  r = run_nsgraph({"generate", "--print-config", "--set", "crops.min_lidar_coverge=0.2"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("did you mean 'crops.min_lidar_coverage'"), std::string::npos) << r.err;
  // A relation between keys names the source of the key it blames.
  TempDir dir("config-relations");
  write_text(dir / "buffer.json", R"({"splits": {"buffer_m": 10}})");
  r = run_nsgraph({"generate", "--print-config", "--config", (dir / "buffer.json").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find((dir / "buffer.json").string() + ": splits.buffer_m"), std::string::npos) << r.err;
  // Flags for string keys take their text as written.
  r = run_nsgraph({"generate", "--print-config", "--version", "1.0"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["version"], "1.0");
}

TEST(GenerateConfig, ListOptionsCoversEveryKeyOfTheResolvedConfig) {
  const std::set<std::string> listed = expect_listed_keys_are_the_config_leaves("generate");
  const CommandResult text = run_nsgraph({"generate", "--list-options"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  for (const std::string& key : listed) EXPECT_NE(text.out.find(key + "  "), std::string::npos) << key;
}

TEST(GenerateConfig, SchemaSampleAndDocsEqualWhatTheDeclarationsGive) {
  const CommandResult schema = run_nsgraph({"generate", "--list-options", "--format", "schema"});
  ASSERT_EQ(schema.exit_code, 0) << schema.err;
  EXPECT_EQ(json::parse(schema.out), json::parse(read_file(source_dir() / "schemas/v1/generate-config.schema.json")))
      << "make regen regenerates it: nsgraph generate --list-options --format schema > "
         "schemas/v1/generate-config.schema.json";
  const CommandResult defaults = run_nsgraph({"generate", "--print-config"});
  ASSERT_EQ(defaults.exit_code, 0) << defaults.err;
  EXPECT_EQ(json::parse(defaults.out), json::parse(read_file(source_dir() / "samples/generate.json")))
      << "make regen regenerates it: nsgraph generate --print-config > samples/generate.json";
  // docs/options.md: a title, then each command's section as its --format md prints it.
  std::string sections;
  for (const char* command : {"generate", "synth", "train", "frames", "graphify"}) {
    const CommandResult md = run_nsgraph({command, "--list-options", "--format", "md"});
    ASSERT_EQ(md.exit_code, 0) << md.err;
    sections += (sections.empty() ? "" : "\n") + md.out;
  }
  const std::string doc = read_file(source_dir() / "docs/options.md");
  const size_t first = doc.find("## `nsgraph generate` options");
  ASSERT_NE(first, std::string::npos);
  EXPECT_EQ(doc.substr(first), sections)
      << "make regen regenerates the sections: nsgraph <generate|synth|train|frames|graphify> --list-options "
         "--format md, joined by an empty line, after the title";
}

TEST(GenerateConfig, CheckOfACodeBuiltConfigUsesTheDeclarations) {
  pipeline::GenerateConfig c;
  EXPECT_NO_THROW(c.validate(/*require_inputs=*/false));
  c.raster.camera.occlusion_window_px = 513;
  try {
    c.validate(false);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.record(), "camera.occlusion_window_px");
  }
  // The library's own entry points take the same declaration.
  raster::CameraOptions cam;
  cam.jpeg_scale_denom = 3;
  EXPECT_THROW(cam.validate(), ConfigError);
}

// Runs `inspect layers` over the bounds of the first tile of each split of `dataset` with
// the config `extra` added to e2e.json, and compares every raster member with the tile's.
// Returns the number of members compared.
size_t compare_inspect_with_tiles(const fs::path& dataset, const std::vector<std::string>& extra) {
  size_t compared = 0;
  const io::Dataset ds = io::Dataset::open(dataset);
  for (const char* split : {"train", "test"}) {
    ds.for_each_tile(split, [&](const io::DatasetTile& t) {
      const json meta = t.json("meta.json");
      const json& b = meta["bounds_m"];
      const std::string location = meta["location"].get<std::string>();
      TempDir dir("inspect-vs-generate");
      std::vector<std::string> args = {"inspect",
                                       "layers",
                                       "--quiet",
                                       "--config",
                                       (source_dir() / "tests/data/generate/e2e.json").string(),
                                       "--dataroot",
                                       e2e_release().string(),
                                       "--location",
                                       location,
                                       "--out",
                                       dir.path().string(),
                                       "--bbox",
                                       b[0].dump() + "," + b[1].dump() + "," + b[2].dump() + "," + b[3].dump()};
      args.insert(args.end(), extra.begin(), extra.end());
      const CommandResult r = run_nsgraph(args);
      EXPECT_EQ(r.exit_code, 0) << r.err;
      if (r.exit_code != 0) return false;
      for (const io::TileMember* m : io::raster_members()) {
        const io::Raster tile = t.raster(m->file);
        const std::string bytes = read_file(dir / (location + "." + m->file));
        const io::Raster window =
            io::decode_geotiff(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), m->file);
        EXPECT_EQ(window.width, tile.width) << t.key << " " << m->file;
        EXPECT_EQ(window.bands, tile.bands) << t.key << " " << m->file;
        EXPECT_TRUE(window.data == tile.data) << t.key << " " << m->file;
        ++compared;
      }
      return false;  // one tile per split
    });
  }
  return compared;
}

// `inspect layers` runs generate's chain: over a tile's bounds it gives the tile's layers.
TEST(InspectLayers, EqualsTheTilesGenerateCutsFromTheSameConfig) {
  EXPECT_EQ(compare_inspect_with_tiles(e2e_dataset(), {}), 2 * io::raster_members().size());
}

// The same with semantics from nuScenes-lidarseg (the source `inspect layers` once lacked).
TEST(InspectLayers, HonoursTheLidarsegSemanticSource) {
  TempDir dir("gen-lidarseg");
  std::vector<std::string> args = e2e_generate_args(dir.path());
  args.insert(args.end(), {"--set", "camera.semantic_source=lidarseg"});
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(compare_inspect_with_tiles(dir.path(), {"--set", "camera.semantic_source=lidarseg"}),
            2 * io::raster_members().size());
  // The option took effect: some tile's semantics differ from the masks' dataset.
  bool differs = false;
  const io::Dataset masks = io::Dataset::open(e2e_dataset()), lidarseg = io::Dataset::open(dir.path());
  std::map<std::string, std::vector<uint8_t>> by_key;
  masks.for_each_tile("", [&](const io::DatasetTile& t) {
    by_key[t.key] = t.raster("semantic.tif").data;
    return true;
  });
  lidarseg.for_each_tile("", [&](const io::DatasetTile& t) {
    differs = differs || by_key[t.key] != t.raster("semantic.tif").data;
    return true;
  });
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace nsg::test
