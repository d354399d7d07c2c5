// Scoring a generated dataset: the ground truth is what its manifest lists, nothing else
// in its folders (a host's dataset may hold a shard left from an earlier run).
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "nsg/metrics/receipt.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;

// A perfect submission of the e2e dataset's test split (its graphs as submission tiles).
fs::path perfect_submission(const fs::path& dataset, const fs::path& dir) {
  const fs::path out = dir / "perfect.json";
  nlohmann::json tiles = nlohmann::json::object();
  const nlohmann::json manifest = read_json(dataset / "manifest.json");
  for (const auto& shard : manifest["shards"]) {
    if (shard["split"] != "test") continue;
    const fs::path unpacked = dir / "unpacked" / shard["name"].get<std::string>();
    fs::create_directories(unpacked);
    const CommandResult t =
        run_program({"tar", "-xf", (dataset / shard["file"].get<std::string>()).string(), "-C", unpacked.string()});
    EXPECT_EQ(t.exit_code, 0) << t.err;
    for (const auto& e : fs::directory_iterator(unpacked)) {
      const std::string name = e.path().filename().string();
      if (name.size() < 11 || name.substr(name.size() - 11) != ".graph.json") continue;
      const nlohmann::json g = read_json(e.path());
      nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
      std::map<std::string, size_t> index;
      for (const auto& n : g["nodes"]) {
        index[n["id"].dump()] = nodes.size();
        nodes.push_back({n["u"], n["v"]});
      }
      for (const auto& ed : g["edges"]) edges.push_back({index.at(ed["source"].dump()), index.at(ed["target"].dump())});
      tiles[name.substr(0, name.size() - 11)] = {{"nodes", nodes}, {"edges", edges}};
    }
  }
  write_text(out, nlohmann::json({{"schema_version", "1"}, {"tiles", tiles}}).dump());
  return out;
}

TEST(ScoreDataset, LeftoverShardIsRefusedByNameAndTheListedOnesScore) {
  TempDir dir("score-dataset");
  const fs::path ds = dir / "dataset";
  fs::copy(e2e_dataset(), ds, fs::copy_options::recursive);
  const fs::path submission = perfect_submission(ds, dir.path());

  CommandResult r = run_nsgraph({"score", "--quiet", "--ground-truth", ds.string(), "--submission", submission.string(),
                                 "--out", (dir / "r.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = read_json(dir / "r.json");
  EXPECT_EQ(report["ground_truth_verification"], "sha256");
  EXPECT_EQ(report["aggregate"]["mean"]["apls"], 1.0);
  EXPECT_EQ(report["aggregate"]["n_missing_predictions"], 0);
  r = run_nsgraph({"score", "--quiet", "--ground-truth", ds.string(), "--submission", submission.string(),
                   "--no-verify", "--out", (dir / "r2.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_json(dir / "r2.json")["ground_truth_verification"], "sizes");

  // A train shard copied in under a test shard's name the manifest does not list.
  fs::copy_file(ds / "shards" / "train-000000.tar", ds / "shards" / "test-000009.tar");
  r = run_nsgraph({"score", "--quiet", "--ground-truth", ds.string(), "--submission", submission.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("shards/test-000009.tar"), std::string::npos) << r.err;
  // validate --submission reads the same manifest: the same key set, nothing extra or missing.
  r = run_nsgraph({"validate", "--submission", submission.string(), "--dataset", ds.string(), "--split", "test"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  fs::remove(ds / "shards" / "test-000009.tar");

  // A listed shard replaced by another one's bytes; a listed shard deleted.
  fs::copy_file(ds / "shards" / "test-000000.tar", ds / "shards" / "test-000001.tar",
                fs::copy_options::overwrite_existing);
  r = run_nsgraph({"score", "--quiet", "--ground-truth", ds.string(), "--submission", submission.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("test-000001.tar"), std::string::npos) << r.err;
  fs::remove(ds / "shards" / "test-000001.tar");
  r = run_nsgraph({"score", "--quiet", "--ground-truth", ds.string(), "--submission", submission.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("test-000001"), std::string::npos) << r.err;
}

// Without --split, score takes the split the submission's keys are tiles of (it scored
// "test" whatever the keys were); keys of several splits are refused, naming the counts.
TEST(ScoreDataset, TheSplitComesFromTheSubmissionsKeys) {
  TempDir dir("score-split");
  const fs::path ds = e2e_dataset();
  const fs::path test_sub = perfect_submission(ds, dir.path());
  const auto score = [&](const fs::path& sub, std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"score",      "--ground-truth", ds.string(), "--submission",
                                     sub.string(), "--no-verify",    "--out",     (dir / "r.json").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_nsgraph(args);
  };
  CommandResult r = score(test_sub);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_json(dir / "r.json")["split"], "test");
  EXPECT_EQ(read_json(dir / "r.json")["receipt"]["ground_truth"]["split"], "test");

  // One train key: scored as train (every other train tile missing).
  const nlohmann::json manifest = read_json(ds / "manifest.json");
  std::string train_key;
  for (const auto& shard : manifest["shards"])
    if (shard["split"] == "train" && train_key.empty()) train_key = shard["first_key"];
  ASSERT_FALSE(train_key.empty());
  nlohmann::json sub = read_json(test_sub);
  const nlohmann::json some_tile = sub["tiles"].begin().value();
  const fs::path train_sub = dir / "train.json";
  write_text(train_sub, nlohmann::json({{"schema_version", "1"}, {"tiles", {{train_key, some_tile}}}}).dump());
  r = score(train_sub);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json train = read_json(dir / "r.json");
  EXPECT_EQ(train["split"], "train");
  EXPECT_EQ(train["aggregate"]["n_missing_predictions"].get<int>(),
            manifest["counts"]["train"]["tiles"].get<int>() - 1);

  sub["tiles"][train_key] = some_tile;
  const fs::path mixed = dir / "mixed.json";
  write_text(mixed, sub.dump());
  fs::remove(dir / "r.json");
  r = score(mixed);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("submission.keys"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(test: " + std::to_string(sub["tiles"].size() - 1) + ", train: 1); give --split"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "r.json"));
  // Given, the split is the user's: the train key is an extra tile of test.
  r = score(mixed, {"--split", "test"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_json(dir / "r.json")["aggregate"]["n_extra_predictions"], 1);
}

}  // namespace
}  // namespace nsg::test

namespace nsg::test {
namespace {

// A second generate into a folder that holds a dataset of another config would leave the
// old shards beside the new ones: refused, --overwrite removes the old dataset first; the
// same config resumes.
TEST(GenerateOverwrite, AnOlderDatasetIsRefusedUnlessOverwritten) {
  TempDir dir("generate-overwrite");
  const fs::path out = dir / "dataset";
  fs::copy(e2e_dataset(), out, fs::copy_options::recursive);
  std::vector<std::string> args = e2e_generate_args(out);
  CommandResult r = run_nsgraph(args);  // the same config: resumed, every item verified
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(tree_hashes(out), tree_hashes(e2e_dataset())) << "resume changed the dataset";
  write_text(out / "notes.txt", "the user's own file");

  args.insert(args.end(), {"--set", "output.tiles_per_shard=2"});
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("older dataset"), std::string::npos) << r.err;

  args.push_back("--overwrite");
  r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json manifest = read_json(out / "manifest.json");
  std::set<std::string> listed, present;
  for (const auto& s : manifest["shards"]) listed.insert(s["file"].get<std::string>());
  for (const auto& e : fs::directory_iterator(out / "shards")) present.insert("shards/" + e.path().filename().string());
  EXPECT_EQ(present, listed);                  // no shard of the old dataset left
  EXPECT_TRUE(fs::exists(out / "notes.txt"));  // only the dataset's own entries go
}

// --overwrite removes only the files a manifest or share record of ours lists: a decoy
// folder (shards/ and maps/ without either) and a user's file beside a dataset are named
// and the run refused, nothing removed.
TEST(GenerateOverwrite, RemovesOnlyWhatOurDocumentsList) {
  TempDir dir("generate-overwrite-decoy");
  const fs::path decoy = dir / "decoy";
  write_text(decoy / "shards" / "mine.tar", "the user's tar");
  write_text(decoy / "maps" / "boston-seaport" / "notes.txt", "the user's notes");
  std::vector<std::string> args = e2e_generate_args(decoy);
  args.push_back("--overwrite");
  CommandResult r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("shards/mine.tar"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(decoy / "shards" / "mine.tar"), "the user's tar");
  EXPECT_EQ(read_text(decoy / "maps" / "boston-seaport" / "notes.txt"), "the user's notes");

  const fs::path out = dir / "dataset";
  fs::copy(e2e_dataset(), out, fs::copy_options::recursive);
  write_text(out / "shards" / "README.txt", "the user's");
  const auto before = tree_hashes(out);
  args = e2e_generate_args(out);
  args.insert(args.end(), {"--set", "output.tiles_per_shard=2", "--overwrite"});
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("shards/README.txt"), std::string::npos) << r.err;
  EXPECT_EQ(tree_hashes(out), before) << "nothing removed before the refusal";

  // --out the release itself (a copy of the tiny one): refused, naming --dataroot.
  const fs::path release = dir / "release";
  fs::copy(tiny_release(), release, fs::copy_options::recursive);
  args = e2e_generate_args(release);
  args[5] = release.string();  // --dataroot
  r = run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--dataroot"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(release / "manifest.json"));
  EXPECT_FALSE(fs::exists(release / "parts"));
}

// merge --overwrite walks the dataset's folders without following links: a maps/ that
// is a link out of the dataset is refused, the files it points at untouched.
TEST(MergeOverwrite, ALinkedMapsFolderIsRefusedNotFollowed) {
  TempDir dir("merge-linked-maps");
  const fs::path out = dir / "dataset";
  fs::copy(e2e_dataset(), out, fs::copy_options::recursive);
  fs::rename(out / "maps", dir / "elsewhere");
  write_text(dir / "elsewhere" / "precious.txt", "not the dataset's");
  fs::create_directory_symlink(dir / "elsewhere", out / "maps");
  fs::remove(out / "manifest.json");
  const CommandResult r = run_nsgraph({"merge", "--out", out.string(), "--overwrite"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("symbolic link"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(dir / "elsewhere" / "precious.txt"), "not the dataset's");
}

}  // namespace
}  // namespace nsg::test

namespace nsg::test {
namespace {

// A mistyped split is named with the ones there are, by every command that takes --split.
TEST(UnknownSplit, EveryCommandNamesItAndTheListedSplits) {
  TempDir dir("unknown-split");
  const std::string ds = e2e_dataset().string();
  const fs::path empty = dir / "empty.json";
  write_text(empty, R"({"schema_version":"1","tiles":{}})");
  const std::vector<std::vector<std::string>> commands = {
      {"preview", ds, "--out", (dir / "p").string(), "--split", "tst"},
      {"score", "--ground-truth", ds, "--submission", empty.string(), "--split", "tst"},
      {"validate", "--submission", empty.string(), "--dataset", ds, "--split", "tst"},
      {"train", "--dataset", ds, "--split", "tst", "--model", (dir / "m.yml.gz").string()},
  };
  for (const auto& args : commands) {
    const CommandResult r = run_nsgraph(args);
    EXPECT_EQ(r.exit_code, 2) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("split 'tst'"), std::string::npos) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("(test, train)"), std::string::npos) << args[0] << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "p")) << "preview made its folder before refusing";
}

}  // namespace
}  // namespace nsg::test

namespace nsg::test {
namespace {

std::vector<std::string> score_args(const fs::path& ds, const fs::path& sub) {
  return {"score", "--quiet", "--ground-truth", ds.string(), "--submission", sub.string(), "--format", "csv"};
}

// A score report's receipt names what was scored and with what; --verify-receipt
// recomputes it from the same inputs ("same", also from another copy of the dataset) and
// names what differs: another submission, the report's numbers edited, another dataset.
TEST(ScoreReceipt, RecomputesSameAndNamesWhatDiffers) {
  TempDir dir("score-receipt");
  const fs::path ds = dir / "dataset";
  fs::copy(e2e_dataset(), ds, fs::copy_options::recursive);
  const fs::path sub = perfect_submission(ds, dir.path());
  std::vector<std::string> args = score_args(ds, sub);
  args.insert(args.end(), {"--out", (dir / "r.json").string(), "--max-file-mb", "200"});
  CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = read_json(dir / "r.json");
  const nlohmann::json& receipt = report["receipt"];
  EXPECT_EQ(receipt["ground_truth"]["kind"], "dataset");
  EXPECT_EQ(receipt["ground_truth"]["manifest_sha256"], sha256_file(ds / "manifest.json"));
  EXPECT_EQ(receipt["ground_truth"]["split"], "test");
  EXPECT_EQ(receipt["ground_truth"]["verification"], "sha256");
  EXPECT_EQ(receipt["submission"]["sha256"], sha256_file(sub));
  EXPECT_EQ(receipt["submission"]["bytes"], fs::file_size(sub));
  EXPECT_EQ(receipt["toolkit"]["name"], "nsgraph");
  EXPECT_FALSE(receipt["toolkit"]["git_commit"].get<std::string>().empty());
  EXPECT_EQ(receipt["metrics_version"], report["metrics_version"]);
  EXPECT_EQ(receipt["limits"]["max_file_bytes"], int64_t{200} << 20);
  EXPECT_EQ(receipt["limits"]["max_nodes_per_tile"], 5000);
  EXPECT_EQ(receipt["options"]["params"], report["params"]);
  EXPECT_EQ(receipt["options"]["verify_ground_truth"], true);
  EXPECT_EQ(receipt["results_sha256"].get<std::string>().size(), 64u);

  const auto verify = [&](const fs::path& receipt_file, const fs::path& dataset, const fs::path& submission) {
    std::vector<std::string> a = score_args(dataset, submission);
    a.insert(a.end(), {"--verify-receipt", receipt_file.string()});
    return run_nsgraph(a);
  };
  r = verify(dir / "r.json", ds, sub);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find(": same"), std::string::npos) << r.out;
  // Another machine: the dataset and the submission elsewhere, the same bytes.
  const fs::path elsewhere = dir / "elsewhere";
  fs::create_directories(elsewhere);
  fs::copy(ds, elsewhere / "dataset", fs::copy_options::recursive);
  fs::copy_file(sub, elsewhere / "sub.json");
  r = verify(dir / "r.json", elsewhere / "dataset", elsewhere / "sub.json");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find(": same"), std::string::npos) << r.out;
  // The receipt alone re-verifies too (its results digest).
  write_text(dir / "receipt.json", receipt.dump());
  r = verify(dir / "receipt.json", ds, sub);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;

  // Another submission: one tile dropped.
  nlohmann::json other = read_json(sub);
  other["tiles"].erase(other["tiles"].begin());
  write_text(dir / "other.json", other.dump());
  r = verify(dir / "r.json", ds, dir / "other.json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("differs"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("submission sha256: recorded " + sha256_file(sub)), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("results: /tiles/"), std::string::npos) << r.out;

  // The report's numbers edited after scoring.
  nlohmann::json edited = report;
  edited["aggregate"]["mean"]["apls"] = 0.99;
  write_text(dir / "edited.json", edited.dump(1));
  r = verify(dir / "edited.json", ds, sub);
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("changed after scoring"), std::string::npos) << r.out;

  // Another dataset: the manifest differs (here: one more line of whitespace).
  write_text(elsewhere / "dataset" / "manifest.json", read_text(ds / "manifest.json") + "\n");
  r = verify(dir / "r.json", elsewhere / "dataset", sub);
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("dataset manifest sha256: recorded " + sha256_file(ds / "manifest.json")), std::string::npos)
      << r.out;

  // A receipt from a stranger without its options: exit 2 naming the field.
  nlohmann::json broken = receipt;
  broken.erase("options");
  write_text(dir / "broken.json", broken.dump());
  r = verify(dir / "broken.json", ds, sub);
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("/receipt/options"), std::string::npos) << r.err;
}

// A receipt verifies, it never configures: --verify-receipt scores with the verifier's own
// options and limits, so a forged receipt cannot make it run out of memory (a tiny
// geo_step_px is out of range: exit 2), lift its limits (a note, the verifier's hold) or
// pass other options off as the defaults (a difference); and per-tile values are compared,
// so a report whose tiles' values were swapped (aggregates equal, digest re-made) differs.
TEST(ScoreReceipt, AReceiptVerifiesButNeverConfigures) {
  TempDir dir("score-receipt-forged");
  const fs::path ds = e2e_dataset();
  nlohmann::json sub = read_json(perfect_submission(ds, dir.path()));
  ASSERT_GE(sub["tiles"].size(), 2u);
  const std::string emptied = sub["tiles"].begin().key();
  sub["tiles"][emptied] = {{"nodes", nlohmann::json::array()}, {"edges", nlohmann::json::array()}};
  write_text(dir / "sub.json", sub.dump());
  std::vector<std::string> args = score_args(ds, dir / "sub.json");
  args.insert(args.end(), {"--out", (dir / "r.json").string()});
  ASSERT_EQ(run_nsgraph(args).exit_code, 0);
  const nlohmann::json report = read_json(dir / "r.json");
  const auto verify = [&](const nlohmann::json& doc) {
    write_text(dir / "forged.json", doc.dump());
    std::vector<std::string> a = score_args(ds, dir / "sub.json");
    a.insert(a.end(), {"--verify-receipt", (dir / "forged.json").string()});
    return run_nsgraph(a);
  };
  ASSERT_EQ(verify(report).exit_code, 0);

  nlohmann::json forged = report;
  forged["receipt"]["options"]["params"]["geo_step_px"] = 1e-6;
  CommandResult r = verify(forged);
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("geo_step_px"), std::string::npos) << r.err;

  forged = report;
  forged["receipt"]["limits"]["max_file_bytes"] = int64_t{1} << 50;
  forged["receipt"]["limits"]["max_path_work_per_tile"] = int64_t{1} << 50;
  r = verify(forged);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("note: limits: recorded"), std::string::npos) << r.out;

  forged = report;
  forged["receipt"]["options"]["params"]["snap_m"] = 6.0;
  r = verify(forged);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("options: recorded"), std::string::npos) << r.out;

  forged = report;
  std::string other;
  for (const auto& [key, tile] : report["tiles"].items())
    if (key != emptied && tile["apls"] != report["tiles"][emptied]["apls"]) other = key;
  ASSERT_FALSE(other.empty());
  std::swap(forged["tiles"][emptied], forged["tiles"][other]);
  forged["receipt"]["results_sha256"] = metrics::results_sha256(forged);
  r = verify(forged);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("results: /tiles/"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace nsg::test
