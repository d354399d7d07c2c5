// End-to-end tests of `nsgraph generate` / `merge` on a small synthetic release.
#include <gtest/gtest.h>

#include <csignal>
#include <map>
#include <set>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "nsg/io/dataset.h"
#include "nsg/io/raster.h"
#include "nsg/io/tar.h"
#include "nsg/io/tile_members.h"
#include "nsg/preview/preview.h"
#include "nsg/pipeline/tile_files.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace nsg::test {
namespace {

// Tiles of a dataset as {key → {suffix → bytes}}, read through the shards of the manifest.
std::map<std::string, std::map<std::string, std::vector<uint8_t>>> read_tiles(const fs::path& dataset,
                                                                              const json& manifest) {
  std::map<std::string, std::map<std::string, std::vector<uint8_t>>> tiles;
  for (const json& shard : manifest["shards"]) {
    io::TarReader reader(dataset / shard["file"].get<std::string>());
    io::TarMember m;
    while (reader.next(m)) {
      const size_t dot = m.name.find('.');
      tiles[m.name.substr(0, dot)][m.name.substr(dot + 1)] = m.bytes;
    }
  }
  return tiles;
}

TEST(Generate, EveryTileHasEveryFileReadableAndCounted) {
  const fs::path dataset = e2e_dataset();
  const json manifest = read_json(dataset / "manifest.json");
  EXPECT_EQ(manifest["schema_version"], "1");
  const int size = manifest["tile_format"]["size_px"].get<int>();
  ASSERT_GT(manifest["counts"]["train"]["tiles"].get<int>(), 0);
  ASSERT_GT(manifest["counts"]["test"]["tiles"].get<int>(), 0);
  for (const json& shard : manifest["shards"]) {
    const fs::path file = dataset / shard["file"].get<std::string>();
    EXPECT_EQ(sha256_file(file), shard["sha256"]) << file;
    EXPECT_EQ(fs::file_size(file), shard["bytes"].get<uint64_t>()) << file;
  }
  const auto tiles = read_tiles(dataset, manifest);
  EXPECT_EQ(static_cast<int64_t>(tiles.size()), manifest["counts"]["total_tiles"].get<int64_t>());
  std::map<std::string, int> per_split;
  for (const auto& [key, files] : tiles) {
    ASSERT_EQ(files.size(), pipeline::tile_file_suffixes().size()) << key;
    for (const std::string& suffix : pipeline::tile_file_suffixes()) {
      ASSERT_TRUE(files.count(suffix)) << key << "." << suffix;
      if (suffix.ends_with(".tif")) {
        const io::Raster r = io::decode_geotiff(files.at(suffix), key + "." + suffix);
        EXPECT_EQ(r.width, size);
        EXPECT_EQ(r.height, size);
        EXPECT_EQ(r.bands, suffix == "rgb.tif" ? 3 : 1);
        EXPECT_EQ(r.type == io::SampleType::kFloat32, suffix == "vehicle.tif");
      }
    }
    const json meta = json::parse(files.at("meta.json"));
    EXPECT_EQ(meta["key"], key);
    EXPECT_GE(meta["coverage"]["lidar"].get<double>(), manifest["config"]["crops"]["min_lidar_coverage"].get<double>());
    ++per_split[meta["split"].get<std::string>()];
  }
  for (const char* split : {"train", "val", "test"})
    EXPECT_EQ(per_split[split], manifest["counts"][split]["tiles"].get<int>()) << split;
}

TEST(Generate, NoTestPixelInsideOrNearATrainRegion) {
  const fs::path dataset = e2e_dataset();
  const json manifest = read_json(dataset / "manifest.json");
  const double buffer_m = manifest["config"]["splits"]["buffer_m"].get<double>();
  const json& regions = manifest["locations"][0]["regions"];
  const auto tiles = read_tiles(dataset, manifest);
  for (const auto& [key, files] : tiles) {
    const json meta = json::parse(files.at("meta.json"));
    const std::vector<double> b = meta["bounds_m"].get<std::vector<double>>();
    bool inside_own = false;
    for (const json& r : regions) {
      const std::vector<double> rb = r["bounds_m"].get<std::vector<double>>();
      if (r["split"] == meta["split"]) {
        inside_own |= b[0] >= rb[0] - 1e-9 && b[1] >= rb[1] - 1e-9 && b[2] <= rb[2] + 1e-9 && b[3] <= rb[3] + 1e-9;
      } else {
        // Gap between the tile and a region of another split.
        const double dx = std::max({0.0, rb[0] - b[2], b[0] - rb[2]});
        const double dy = std::max({0.0, rb[1] - b[3], b[1] - rb[3]});
        EXPECT_GE(std::hypot(dx, dy), buffer_m - 1e-6) << key << " vs region " << r["name"];
      }
    }
    EXPECT_TRUE(inside_own) << key << " lies wholly inside a region of its split";
  }
}

TEST(Generate, GraphNodesLieInsideTheirTiles) {
  const fs::path dataset = e2e_dataset();
  const json manifest = read_json(dataset / "manifest.json");
  const double size = manifest["tile_format"]["size_px"].get<double>();
  size_t nodes = 0;
  for (const auto& [key, files] : read_tiles(dataset, manifest)) {
    const json g = json::parse(files.at("graph.json"));
    const json meta = json::parse(files.at("meta.json"));
    EXPECT_EQ(g["nodes"].size(), meta["counts"]["nodes"].get<size_t>());
    for (const json& n : g["nodes"]) {
      EXPECT_GE(n["u"].get<double>(), -0.5 - 1e-9) << key;
      EXPECT_LE(n["u"].get<double>(), size - 0.5 + 1e-9) << key;
      EXPECT_GE(n["v"].get<double>(), -0.5 - 1e-9) << key;
      EXPECT_LE(n["v"].get<double>(), size - 0.5 + 1e-9) << key;
      ++nodes;
    }
    for (const json& e : g["edges"]) {
      EXPECT_LT(e["source"].get<size_t>(), g["nodes"].size());
      EXPECT_LT(e["target"].get<size_t>(), g["nodes"].size());
    }
  }
  EXPECT_GT(nodes, 50u);
}

TEST(Generate, PythonReadsAShardAndDecodesEveryLayer) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "optional tool /usr/bin/python3 (Debian's) not installed";
  const fs::path dataset = e2e_dataset();
  const json manifest = read_json(dataset / "manifest.json");
  const fs::path shard = dataset / manifest["shards"][0]["file"].get<std::string>();
  const int size = manifest["tile_format"]["size_px"].get<int>();
  const std::string script = R"(
import io, json, sys, tarfile
import numpy as np
from PIL import Image
size = int(sys.argv[2])
keys = {}
with tarfile.open(sys.argv[1]) as tar:
    for m in tar.getmembers():
        key, suffix = m.name.split('.', 1)
        keys.setdefault(key, {})[suffix] = tar.extractfile(m).read()
for key, files in keys.items():
    lidar = np.array(Image.open(io.BytesIO(files['lidar.tif'])))
    rgb = np.array(Image.open(io.BytesIO(files['rgb.tif'])))
    sem = np.array(Image.open(io.BytesIO(files['semantic.tif'])))
    veh = np.array(Image.open(io.BytesIO(files['vehicle.tif'])))
    cov = np.array(Image.open(io.BytesIO(files['coverage.tif'])))
    meta = json.loads(files['meta.json']); graph = json.loads(files['graph.json'])
    assert lidar.shape == (size, size) and lidar.dtype == np.uint8
    assert rgb.shape == (size, size, 3) and rgb.dtype == np.uint8
    assert sem.shape == (size, size) and veh.dtype == np.float32
    assert ((veh == -1) | ((veh >= 0) & (veh < 1))).all()
    assert ((cov & 1) > 0).sum() == (lidar > 0).sum()
    assert abs((lidar > 0).mean() - meta['coverage']['lidar']) < 1e-9
    assert len(graph['nodes']) == meta['counts']['nodes']
print(len(keys))
)";
  const CommandResult r = run_program({"/usr/bin/python3", "-c", script, shard.string(), std::to_string(size)});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(std::stoi(r.out), manifest["shards"][0]["tiles"].get<int>());
}

TEST(Generate, OneThreadAndThreeSharesGiveTheSameBytes) {
  const fs::path reference = e2e_dataset();
  TempDir one("gen-1thread"), three("gen-3shares");
  std::vector<std::string> args = e2e_generate_args(one.path());
  args.insert(args.end(), {"--threads", "1"});
  ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  EXPECT_EQ(tree_hashes(one.path()), tree_hashes(reference));
  for (int i = 0; i < 3; ++i) {
    args = e2e_generate_args(three.path());
    args.insert(args.end(), {"--shard-index", std::to_string(i), "--num-shards", "3"});
    const CommandResult r = run_nsgraph(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(fs::exists(three / "manifest.json")) << "a share of several must not write the manifest";
  }
  const CommandResult merged = run_nsgraph({"merge", "--out", three.path().string()});
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(tree_hashes(three.path()), tree_hashes(reference));
}

TEST(Generate, MergeNamesAMissingShareAndACorruptShard) {
  TempDir dir("gen-merge");
  for (int i : {0, 2}) {
    std::vector<std::string> args = e2e_generate_args(dir.path());
    args.insert(args.end(), {"--shard-index", std::to_string(i), "--num-shards", "3"});
    ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  }
  CommandResult r = run_nsgraph({"merge", "--out", dir.path().string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("share 1 of 3: missing"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));

  std::vector<std::string> args = e2e_generate_args(dir.path());
  args.insert(args.end(), {"--shard-index", "1", "--num-shards", "3"});
  ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  // Flip one byte of a shard: merge must name it, a rerun of its share must redo it.
  const json record = read_json(dir / "parts/share-000000-of-000003.json");
  std::string victim;
  for (const json& item : record["items"])
    if (item["kind"] == "shard") victim = item["files"][0]["file"].get<std::string>();
  ASSERT_FALSE(victim.empty());
  std::string bytes = read_file(dir / victim);
  bytes[bytes.size() / 2] ^= 0x01;
  write_text(dir / victim, bytes);
  r = run_nsgraph({"merge", "--out", dir.path().string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(victim), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("corrupt"), std::string::npos) << r.err;

  args = e2e_generate_args(dir.path());
  args.insert(args.end(), {"--shard-index", "0", "--num-shards", "3"});
  ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  r = run_nsgraph({"merge", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(tree_hashes(dir.path()), tree_hashes(e2e_dataset()));
}

// The release named another way — relative to the working folder, or through a link — is the
// same config: the rerun resumes (every shard verified, none rewritten), not "another config".
TEST(Generate, ARerunNamingTheReleaseAnotherWayResumes) {
  TempDir dir("gen-resume-spelling");
  ASSERT_EQ(run_nsgraph(e2e_generate_args(dir / "out")).exit_code, 0);
  std::map<std::string, fs::file_time_type> written;
  for (const auto& e : fs::recursive_directory_iterator(dir / "out/shards"))
    written[e.path().string()] = fs::last_write_time(e.path());
  ASSERT_FALSE(written.empty());
  fs::create_directory_symlink(e2e_release(), dir / "link");
  for (const fs::path& release : {fs::relative(e2e_release(), fs::current_path()), dir.path() / "link"}) {
    SCOPED_TRACE(release.string());
    std::vector<std::string> args = e2e_generate_args(dir / "out");
    for (size_t i = 0; i + 1 < args.size(); ++i)
      if (args[i] == "--dataroot") args[i + 1] = release.string();
    const CommandResult r = run_nsgraph(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const auto& [file, time] : written) EXPECT_EQ(fs::last_write_time(file), time) << file << " was rewritten";
  }
}

// Shares written into a folder an older dataset left a shard and a done-record in: merge
// names the leftovers and writes no manifest; --overwrite removes them and merges.
TEST(Generate, MergeRefusesAnOlderDatasetsLeftoversUnlessOverwritten) {
  TempDir dir("gen-merge-old");
  fs::create_directories(dir / "shards");
  fs::create_directories(dir / "parts");
  write_text(dir / "shards/test-000009.tar", "an older run's shard");
  for (int i = 0; i < 2; ++i) {
    std::vector<std::string> args = e2e_generate_args(dir.path());
    args.insert(args.end(), {"--shard-index", std::to_string(i), "--num-shards", "2"});
    if (i == 0) {  // the older dataset's record only appears after the first share started
      const CommandResult r = run_nsgraph(args);
      EXPECT_EQ(r.exit_code, 2) << "a share started beside another dataset's shards: " << r.err;
      fs::remove(dir / "shards/test-000009.tar");
    }
    ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  }
  write_text(dir / "shards/test-000009.tar", "an older run's shard");
  // An older 5-share run's record (its name and its `share` agree, as generate writes them).
  nlohmann::json older = read_json(dir / "parts/share-000000-of-000002.json");
  older["share"]["count"] = 5;
  write_text(dir / "parts/share-000000-of-000005.json", older.dump());
  fs::last_write_time(dir / "parts/share-000000-of-000005.json",
                      fs::last_write_time(dir / "parts/share-000000-of-000002.json") - std::chrono::hours(1));
  CommandResult r = run_nsgraph({"merge", "--out", dir.path().string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("share-000000-of-000005.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));
  fs::remove(dir / "parts/share-000000-of-000005.json");
  r = run_nsgraph({"merge", "--out", dir.path().string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("shards/test-000009.tar"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));

  // The older run's record lists its shard: --overwrite removes what a record of ours
  // lists, and refuses (removing nothing) while a file no record lists is there.
  older = read_json(dir / "parts/share-000000-of-000002.json");
  older["share"]["count"] = 5;
  older["items"][0]["files"].push_back(
      {{"file", "shards/test-000009.tar"}, {"sha256", std::string(64, '0')}, {"bytes", 1}});
  write_text(dir / "parts/share-000000-of-000005.json", older.dump());
  fs::last_write_time(dir / "parts/share-000000-of-000005.json",
                      fs::last_write_time(dir / "parts/share-000000-of-000002.json") - std::chrono::hours(1));
  write_text(dir / "shards/user-notes.txt", "the user's");
  r = run_nsgraph({"merge", "--out", dir.path().string(), "--overwrite"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("shards/user-notes.txt"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(dir / "shards/test-000009.tar"));
  EXPECT_TRUE(fs::exists(dir / "parts/share-000000-of-000005.json"));
  fs::remove(dir / "shards/user-notes.txt");
  r = run_nsgraph({"merge", "--out", dir.path().string(), "--overwrite"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "shards/test-000009.tar"));
  EXPECT_FALSE(fs::exists(dir / "parts/share-000000-of-000005.json"));
  EXPECT_EQ(read_json(dir / "manifest.json")["shards"], read_json(e2e_dataset() / "manifest.json")["shards"]);
}

// A done-record is an outside file: deep nesting, a mistyped field and a file outside the
// dataset are named (exit 2), never a crash or a manifest pointing at /etc.
TEST(Generate, MergeChecksTheDoneRecordsLikeAnyOutsideFile) {
  TempDir dir("gen-merge-hostile");
  fs::create_directories(dir / "parts");
  const fs::path record = dir / "parts/share-000000-of-000001.json";
  const auto merge_err = [&](const std::string& text) {
    write_text(record, text);
    const CommandResult r = run_nsgraph({"merge", "--out", dir.path().string()});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(record.string()), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "manifest.json"));
    return r.err;
  };
  merge_err(std::string(200000, '[') + std::string(200000, ']'));
  nlohmann::json real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["complete"] = "yes";
  EXPECT_NE(merge_err(real.dump()).find("/complete"), std::string::npos);
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["items"][0]["digest"] = 7;  // read through json::get before the record had a reader
  EXPECT_NE(merge_err(real.dump()).find("/items/0/digest"), std::string::npos);
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["share"]["count"] = 2;  // the name says 1 share
  EXPECT_NE(merge_err(real.dump()).find("/share"), std::string::npos);
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["items"][0]["files"][0]["file"] = "../../etc/hostname";
  EXPECT_NE(merge_err(real.dump()).find("/items/0/files/0/file"), std::string::npos);
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["items"][0]["files"][0]["bytes"] = "many";
  EXPECT_NE(merge_err(real.dump()).find("/items/0/files/0/bytes"), std::string::npos);
  // A config member merge reads, missing: it was read through a dangling reference
  // (heap-use-after-free, found by fuzz_merge).
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["config"].erase("output");
  EXPECT_NE(merge_err(real.dump()).find("/config/output"), std::string::npos);
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["config"]["crops"]["size_px"] = "big";
  EXPECT_NE(merge_err(real.dump()).find("/config"), std::string::npos);
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["config"]["a~/b"] = 1;  // a key no config has: named, never an internal error
  const std::string unknown = merge_err(real.dump());
  EXPECT_NE(unknown.find("/config"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("a~/b"), std::string::npos) << unknown;
  real = read_json(e2e_dataset() / "parts/share-000000-of-000001.json");
  real["plan"][0].erase("map_version");
  EXPECT_NE(merge_err(real.dump()).find("/plan/0/map_version"), std::string::npos);
}

// kill -9 in the middle of a run leaves no half-written shard under its final name, and a
// rerun completes to the same bytes as an uninterrupted run.
TEST(Generate, KilledRunLeavesNoCorruptShardAndRerunCompletes) {
  const fs::path release = e2e_release();  // made before timing the kill
  TempDir dir("gen-kill");
  std::vector<std::string> args = e2e_generate_args(dir.path());
  args.insert(args.end(), {"--threads", "1"});
  std::vector<char*> argv;
  const std::string exe = nsgraph_exe().string();
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  // Kill as soon as the first shard is in place (mid-run), or after 20 s at the latest.
  for (int i = 0; i < 2000 && !fs::exists(dir / "shards/train-000000.tar"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));
  // Every shard visible under its final name is whole (a tar a reader can stream to the end).
  if (fs::exists(dir / "shards"))
    for (const auto& e : fs::directory_iterator(dir / "shards")) {
      if (e.path().extension() != ".tar") continue;
      io::TarReader reader(e.path());
      io::TarMember m;
      EXPECT_NO_THROW(while (reader.next(m)){}) << e.path();
    }
  const CommandResult r = run_nsgraph(e2e_generate_args(dir.path()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(tree_hashes(dir.path()), tree_hashes(e2e_dataset()));
}

TEST(GenerateConfig, UnknownKeysAndBadValuesAreNamed) {
  TempDir dir("gen-config");
  write_text(dir / "bad.json", R"({"crops": {"min_lidar_coverge": 0.3}})");
  CommandResult r = run_nsgraph({"generate", "--config", (dir / "bad.json").string(), "--print-config"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("crops.min_lidar_coverge"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  write_text(dir / "bad2.json", R"({"crops": {"min_lidar_coverage": "half"}})");
  r = run_nsgraph({"generate", "--config", (dir / "bad2.json").string(), "--print-config"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("a number"), std::string::npos) << r.err;
  write_text(dir / "bad3.json", "{\"seed\": 1,");
  r = run_nsgraph({"generate", "--config", (dir / "bad3.json").string(), "--print-config"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bad3.json"), std::string::npos) << r.err;
  r = run_nsgraph({"generate", "--print-config", "--set", "splits.buffer_m=10"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("splits.buffer_m"), std::string::npos) << r.err;
  r = run_nsgraph(
      {"generate", "--dataroot", "/nonexistent-nsg", "--version", "v1.0-mini", "--out", (dir / "out").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/nonexistent-nsg"), std::string::npos) << r.err;
}

TEST(GenerateConfig, DefaultsFileMatchesTheBuiltInDefaultsAndFlagsOverride) {
  const CommandResult builtin = run_nsgraph({"generate", "--print-config"});
  ASSERT_EQ(builtin.exit_code, 0) << builtin.err;
  const CommandResult file =
      run_nsgraph({"generate", "--print-config", "--config", (source_dir() / "samples/generate.json").string()});
  ASSERT_EQ(file.exit_code, 0) << file.err;
  EXPECT_EQ(json::parse(builtin.out), json::parse(file.out));
  const CommandResult flags = run_nsgraph(
      {"generate", "--print-config", "--min-coverage", "0.25", "--set", "crops.placement.test=random", "--seed", "9"});
  ASSERT_EQ(flags.exit_code, 0) << flags.err;
  const json c = json::parse(flags.out);
  EXPECT_EQ(c["crops"]["min_lidar_coverage"], 0.25);
  EXPECT_EQ(c["crops"]["placement"]["test"], "random");
  EXPECT_EQ(c["seed"], 9);
}

}  // namespace
}  // namespace nsg::test

namespace nsg::test {
namespace {

// The folder layout holds the same tile files as the tar shards, and io::Dataset reads
// both the same way.
TEST(Generate, FolderLayoutHoldsTheSameTilesAsTheShards) {
  TempDir dir("gen-folder");
  std::vector<std::string> args = e2e_generate_args(dir.path());
  args.insert(args.end(), {"--layout", "folder"});
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::Dataset tar = io::Dataset::open(e2e_dataset());
  const io::Dataset folder = io::Dataset::open(dir.path());
  EXPECT_TRUE(tar.tar_layout());
  EXPECT_FALSE(folder.tar_layout());
  std::map<std::string, std::map<std::string, std::vector<uint8_t>>> a, b;
  tar.for_each_tile("", [&](const io::DatasetTile& t) {
    a[t.key] = t.files;
    return true;
  });
  folder.for_each_tile("", [&](const io::DatasetTile& t) {
    b[t.key] = t.files;
    return true;
  });
  EXPECT_EQ(static_cast<int64_t>(a.size()), tar.manifest().counts.total_tiles);
  EXPECT_EQ(a, b);
  size_t test_tiles = 0;
  folder.for_each_tile("test", [&](const io::DatasetTile& t) {
    EXPECT_EQ(t.json("meta.json")["split"], "test");
    EXPECT_EQ(t.raster("lidar.tif").width, folder.manifest().tile_format.size_px);
    ++test_tiles;
    return true;
  });
  EXPECT_EQ(static_cast<int64_t>(test_tiles), folder.manifest().counts.test.tiles);
}

}  // namespace
}  // namespace nsg::test

namespace nsg::test {
namespace {

TEST(Stats, CountsAndAreasFollowTheTiles) {
  const fs::path dataset = e2e_dataset();
  const json manifest = read_json(dataset / "manifest.json");
  const CommandResult r = run_nsgraph({"stats", dataset.string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json s = json::parse(r.out);
  const double tile_km2 = std::pow(manifest["tile_format"]["size_px"].get<double>() * 0.2, 2) / 1e6;
  for (const char* split : {"train", "test"}) {
    EXPECT_EQ(s[split]["tiles"], manifest["counts"][split]["tiles"]) << split;
    EXPECT_LE(s[split]["labeled_area_km2"].get<double>(), s[split]["tiles"].get<double>() * tile_km2 + 1e-12);
    EXPECT_GT(s[split]["lane_segments"].get<int>(), 0);
  }
  // Test crops lie on a non-overlapping grid: their union is exactly their sum.
  EXPECT_NEAR(s["test"]["labeled_area_km2"].get<double>(), s["test"]["tiles"].get<double>() * tile_km2, 1e-12);
  EXPECT_EQ(s["all"]["tiles"], manifest["counts"]["total_tiles"]);
  EXPECT_FALSE(s["all"]["semantic_classes"].empty());
  const CommandResult text = run_nsgraph({"stats", dataset.string()});
  EXPECT_NE(text.out.find("area (km²)"), std::string::npos);
  EXPECT_EQ(run_nsgraph({"stats", "/nonexistent-dataset"}).exit_code, 2);
}

// Train crops are cut at random and overlap: stats measures lanes and vehicles on the
// union of the tiles, as the area. Checked against an independent count: lanes sampled
// every 5 mm in map metres, each sample counted in the first tile (key order) whose box
// holds it; vehicle pixels deduplicated by their centres' map coordinates.
TEST(Stats, LanesAndVehiclesAreMeasuredOnTheUnionOfOverlappingCrops) {
  const fs::path dataset = e2e_dataset();
  const CommandResult r = run_nsgraph({"stats", dataset.string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json s = json::parse(r.out);
  struct Tile {
    json meta, graph;
  };
  std::map<std::string, std::vector<Tile>> tiles;  // split → tiles in key order
  std::map<std::string, std::set<std::tuple<std::string, int64_t, int64_t>>> vehicle_centres;
  const io::Dataset ds = io::Dataset::open(dataset);
  ds.for_each_tile("", [&](const io::DatasetTile& t) {
    const json meta = t.json("meta.json");
    const std::string split = meta["split"];
    tiles[split].push_back({meta, t.json("graph.json")});
    const io::Raster vehicle = t.raster("vehicle.tif");
    const double res = meta["resolution_m"], west = meta["bounds_m"][0], north = meta["bounds_m"][3];
    for (int py = 0; py < vehicle.height; ++py)
      for (int px = 0; px < vehicle.width; ++px) {
        float v;
        std::memcpy(&v, vehicle.data.data() + 4 * (static_cast<size_t>(py) * vehicle.width + px), 4);
        if (v < 0.0f) continue;
        // Pixel centres in half pixels: exact integers whichever tile holds the pixel.
        vehicle_centres[split].insert({meta["location"].get<std::string>(),
                                       std::llround((west + (px + 0.5) * res) / res * 2),
                                       std::llround((north - (py + 0.5) * res) / res * 2)});
      }
    return true;
  });
  for (const std::string split : {"train", "test"}) {
    auto& list = tiles[split];
    ASSERT_GT(list.size(), 1u) << split;
    std::sort(list.begin(), list.end(), [](const Tile& a, const Tile& b) { return a.meta["key"] < b.meta["key"]; });
    const auto holds = [](const json& meta, double x, double y) {
      const json& b = meta["bounds_m"];
      return x >= b[0].get<double>() && x <= b[2].get<double>() && y >= b[1].get<double>() && y <= b[3].get<double>();
    };
    double union_m = 0.0, summed_m = 0.0;
    for (size_t i = 0; i < list.size(); ++i) {
      std::map<int64_t, const json*> node_of;
      for (const json& n : list[i].graph["nodes"]) node_of[n["id"].get<int64_t>()] = &n;
      for (const json& e : list[i].graph["edges"]) {
        const json &a = *node_of.at(e["source"]), &c = *node_of.at(e["target"]);
        const double ax = a["x"], ay = a["y"], cx = c["x"], cy = c["y"];
        const double length = std::hypot(cx - ax, cy - ay);
        summed_m += length;
        const int samples = std::max(1, static_cast<int>(std::ceil(length / 0.005)));
        for (int k = 0; k < samples; ++k) {
          const double t = (k + 0.5) / samples, x = ax + t * (cx - ax), y = ay + t * (cy - ay);
          size_t owner = 0;
          while (owner < list.size() &&
                 !(list[owner].meta["location"] == list[i].meta["location"] && holds(list[owner].meta, x, y)))
            ++owner;
          if (owner == i) union_m += length / samples;
        }
      }
    }
    EXPECT_NEAR(s[split]["lane_length_km"].get<double>(), union_m / 1000.0, 1e-3 * union_m / 1000.0) << split;
    const double res = list[0].meta["resolution_m"];
    EXPECT_EQ(s[split]["vehicle_px"].get<int64_t>(), static_cast<int64_t>(vehicle_centres[split].size())) << split;
    EXPECT_NEAR(s[split]["vehicle_area_km2"].get<double>(), vehicle_centres[split].size() * res * res / 1e6, 1e-12);
    // Train crops overlap (the old sum over tiles counted lanes twice), test crops do not.
    if (split == "train") EXPECT_LT(union_m, 0.9 * summed_m);
    else EXPECT_NEAR(union_m, summed_m, 1e-6 * summed_m);
  }
  // Class names, not ids.
  for (const json& name : s["all"]["semantic_classes"]) EXPECT_TRUE(name.is_string()) << name;
}

// Each command that reads a dataset takes it as --dataset; stats and preview keep the
// positional form.
TEST(CliConventions, DatasetIsAnOptionAndStaysPositionalWhereItWas) {
  const std::string ds = e2e_dataset().string();
  const CommandResult a = run_nsgraph({"stats", "--dataset", ds, "--json"});
  const CommandResult b = run_nsgraph({"stats", ds, "--json"});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_EQ(a.out, b.out);
  TempDir tmp("cli-dataset");
  const CommandResult p = run_nsgraph({"preview", "-q", "--dataset", ds, "--out", tmp.path().string(), "--shard", "0"});
  EXPECT_EQ(p.exit_code, 0) << p.err;
}

// stats and the dataset report read tile documents through the checked readers: a
// crafted meta.json or graph.json in a shard is named (exit 2) in bounded time, never a
// crash, a hang or "internal error".
TEST(Stats, CraftedTileDocumentsAreNamed) {
  TempDir dir("stats-hostile");
  const fs::path ds = dir / "dataset";
  fs::copy(e2e_dataset(), ds, fs::copy_options::recursive);
  // Rewrites the first tile's <suffix> in shards/test-000000.tar with `edit` applied.
  const char* rewrite = R"(
import io, json, sys, tarfile
path, suffix, edit = sys.argv[1], sys.argv[2], sys.argv[3]
with tarfile.open(path) as t:
    members = [(m, t.extractfile(m).read()) for m in t.getmembers()]
first = members[0][0].name.split('.', 1)[0]
out = []
for m, data in members:
    if m.name == first + '.' + suffix:
        doc = json.loads(data)
        exec(edit)
        data = json.dumps(doc).encode()
        m.size = len(data)
    out.append((m, data))
with tarfile.open(path, 'w', format=tarfile.USTAR_FORMAT) as t:
    for m, data in out:
        t.addfile(m, io.BytesIO(data))
print(first)
)";
  const fs::path shard = ds / "shards/test-000000.tar";
  const std::string original = read_file(shard);
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"meta.json", "doc['bounds_m'] = []", "/bounds_m"},
      {"meta.json", "doc['size_px'] = 20000", "/size_px"},
      {"meta.json", "del doc['counts']", "/counts"},
      {"meta.json", "doc['split'] = 7", "/split"},
      {"meta.json", "doc['resolution_m'] = 0", "/resolution_m"},
      {"graph.json", "doc['edges'][0]['source'] = 100000000", "edges"},
  };
  for (const auto& [suffix, edit, path] : cases) {
    write_text(shard, original);
    const CommandResult made = run_program({"/usr/bin/python3", "-c", rewrite, shard.string(), suffix, edit});
    ASSERT_EQ(made.exit_code, 0) << made.err;
    const std::string key = made.out.substr(0, made.out.find('\n'));
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"stats", ds.string()},
          std::vector<std::string>{"report", "--quiet", "--dataset", ds.string(), "--out", (dir / "r").string()}}) {
      const CommandResult r = run_nsgraph(args);
      EXPECT_EQ(r.exit_code, 2) << args[0] << " " << edit << ": " << r.err;
      EXPECT_NE(r.err.find(key + "." + suffix), std::string::npos) << args[0] << " " << edit << ": " << r.err;
      EXPECT_NE(r.err.find(path), std::string::npos) << args[0] << " " << edit << ": " << r.err;
    }
  }
}

}  // namespace
}  // namespace nsg::test

namespace nsg::test {
namespace {

TEST(InspectLayers, WritesGeoreferencedLayersOfTheWindowWithCoverage) {
  TempDir dir("inspect-layers");
  const CommandResult r = run_nsgraph({"inspect", "layers", "--dataroot", e2e_release().string(), "--location",
                                       "boston-seaport", "--out", dir.path().string(), "--bbox", "100,60,140,110"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json out = json::parse(r.out);
  EXPECT_EQ(out["size_px"], json::array({200, 250}));
  io::GeoRef geo;
  const std::string lidar_bytes = read_file(dir / "boston-seaport.lidar.tif");
  const io::Raster lidar = io::decode_geotiff(
      std::span(reinterpret_cast<const uint8_t*>(lidar_bytes.data()), lidar_bytes.size()), "lidar", &geo);
  EXPECT_EQ(lidar.width, 200);
  EXPECT_EQ(lidar.height, 250);
  EXPECT_NEAR(geo.x_west_m, 100.0, 1e-9);
  EXPECT_NEAR(geo.y_north_m, 110.0, 1e-9);
  EXPECT_EQ(geo.location, "boston-seaport");
  const std::string cov_bytes = read_file(dir / "boston-seaport.coverage.tif");
  const io::Raster cov =
      io::decode_geotiff(std::span(reinterpret_cast<const uint8_t*>(cov_bytes.data()), cov_bytes.size()), "coverage");
  size_t lidar_px = 0, flagged = 0;
  for (size_t i = 0; i < lidar.data.size(); ++i) {
    lidar_px += lidar.data[i] > 0;
    flagged += (cov.data[i] & 1) != 0;
  }
  EXPECT_EQ(lidar_px, flagged);
  EXPECT_EQ(out["cells"]["lidar"].get<size_t>(), lidar_px);
  EXPECT_GT(lidar_px, 1000u);
  EXPECT_GT(out["cells"]["rgb"].get<size_t>(), 0u);
  for (const char* layer : {"rgb", "semantic", "vehicle"})
    EXPECT_TRUE(fs::exists(dir / (std::string("boston-seaport.") + layer + ".tif"))) << layer;
  EXPECT_EQ(run_nsgraph({"inspect", "layers", "--dataroot", e2e_release().string(), "--location", "boston-seaport",
                         "--out", dir.path().string(), "--bbox", "1,2,3"})
                .exit_code,
            2);
  // Reading every sweep takes minutes on a real city: a progress line per stage in a log
  // (stderr is not a terminal here), never a carriage return.
  EXPECT_NE(r.err.find("lidar sweeps: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("camera images: "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
}

// What QGIS shows of the layers, read back with GDAL (gdal-bin is one of the packages
// `make deps` installs): band names, the semantic layer's colour table (the preview's
// palette, no data grey) and its class names as categories.
TEST(InspectLayers, GisSeesBandNamesColoursAndClassNames) {
  TempDir dir("inspect-layers-gis");
  CommandResult r = run_nsgraph({"inspect", "layers", "-q", "--dataroot", e2e_release().string(), "--location",
                                 "boston-seaport", "--out", dir.path().string(), "--bbox", "100,60,120,80"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto gdalinfo = [&](const std::string& layer) {
    const CommandResult g = run_program({"gdalinfo", "-json", (dir / ("boston-seaport." + layer + ".tif")).string()});
    EXPECT_EQ(g.exit_code, 0) << g.err;
    return json::parse(g.out);
  };
  const json semantic = gdalinfo("semantic");
  const json& band = semantic["bands"][0];
  EXPECT_EQ(band["description"], "semantic: " + io::find_tile_member("semantic")->description);
  EXPECT_EQ(band["colorInterpretation"], "Palette");
  ASSERT_EQ(band["colorTable"]["count"], 256);
  const json& entries = band["colorTable"]["entries"];
  for (int c = 0; c < preview::kSemanticClassCount; ++c) {
    const preview::Rgb rgb = preview::semantic_color(c);
    EXPECT_EQ(entries[c], json::array({rgb.r, rgb.g, rgb.b, 255})) << c;
  }
  // GDAL shows the no-data value's entry transparent.
  EXPECT_EQ(entries[255], json::array({preview::kNoData.r, preview::kNoData.g, preview::kNoData.b, 0}));
  ASSERT_EQ(band["categories"].size(), static_cast<size_t>(preview::kSemanticClassCount)) << band.dump();
  EXPECT_EQ(band["categories"][0], "road");
  EXPECT_EQ(band["categories"][13], "sky_other");
  EXPECT_EQ(band["metadata"][""]["CLASS_1"], "lane_marking") << band.dump();
  EXPECT_EQ(band["noDataValue"], 255);
  const json rgb = gdalinfo("rgb");
  ASSERT_EQ(rgb["bands"].size(), 3u);
  EXPECT_EQ(rgb["bands"][0]["description"], "camera red");
  EXPECT_EQ(rgb["bands"][2]["description"], "camera blue");
  EXPECT_EQ(rgb["bands"][0]["colorInterpretation"], "Red");
  EXPECT_EQ(gdalinfo("vehicle")["bands"][0]["description"], "vehicle: " + io::find_tile_member("vehicle")->description);
  // Still what the library decodes (the palette maps values, it does not change them).
  const std::string bytes = read_file(dir / "boston-seaport.semantic.tif");
  const io::Raster decoded =
      io::decode_geotiff(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), "semantic");
  EXPECT_EQ(decoded.bands, 1);
}

}  // namespace
}  // namespace nsg::test
