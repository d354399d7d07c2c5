#include "generate_fixture.h"

#include <algorithm>
#include <stdexcept>

#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace nsg::test {

namespace {
std::string content_key(const fs::path& file) { return sha256_hex(read_file(file)).substr(0, 16); }
}  // namespace

fs::path e2e_release() {
  const fs::path config = source_dir() / "tests/data/synth/e2e.json";
  return cached_folder("release_e2e", nsgraph_build_key() + "-" + content_key(config), [&](const fs::path& dir) {
    const CommandResult r = run_nsgraph({"synth", "--quiet", "--config", config.string(), "--out", dir.string()});
    if (r.exit_code != 0) throw std::runtime_error("synth e2e failed: " + r.err);
  });
}

fs::path release_with_renamed_scene(const fs::path& release, const std::string& version, const std::string& from,
                                    const std::string& to, const fs::path& dir) {
  fs::create_directories(dir / version);
  for (const auto& e : fs::directory_iterator(release))
    if (e.path().filename() != version) fs::create_symlink(e.path(), dir / e.path().filename());
  for (const auto& e : fs::directory_iterator(release / version)) {
    if (e.path().filename() != "scene.json") {
      fs::create_symlink(e.path(), dir / version / e.path().filename());
      continue;
    }
    std::string text = read_file(e.path());
    const std::string quoted = "\"" + from + "\"";
    const size_t at = text.find(quoted);
    if (at == std::string::npos || text.find(quoted, at + 1) != std::string::npos)
      throw std::runtime_error("scene " + from + " not found once in " + e.path().string());
    text.replace(at, quoted.size(), "\"" + to + "\"");
    write_text(dir / version / "scene.json", text);
  }
  return dir;
}

std::vector<std::string> e2e_generate_args(const fs::path& out) {
  return {"generate",   "--quiet",
          "--config",   (source_dir() / "tests/data/generate/e2e.json").string(),
          "--dataroot", e2e_release().string(),
          "--version",  "v1.0-mini",
          "--out",      out.string()};
}

fs::path e2e_dataset() {
  const fs::path config = source_dir() / "tests/data/generate/e2e.json";
  const fs::path release = e2e_release();
  return cached_folder("dataset_e2e", nsgraph_build_key() + "-" + content_key(config), [&](const fs::path& dir) {
    std::vector<std::string> args = e2e_generate_args(dir);
    args.insert(args.end(), {"--threads", "2"});
    const CommandResult r = run_nsgraph(args);
    if (r.exit_code != 0) throw std::runtime_error("generate e2e failed: " + r.err);
  });
}

std::vector<std::string> e2e_ladder_args(const fs::path& out) {
  std::vector<std::string> args = e2e_generate_args(out);
  args.insert(args.end(), {"--ladder", "--tiles-per-shard", "3"});
  return args;
}

std::vector<std::string> real_keyframe_ladder_args(const fs::path& out) {
  return {"generate",
          "--quiet",
          "--dataroot",
          (source_dir() / "tests/data/real/scene-0061-keyframe").string(),
          "--version",
          "v1.0-mini",
          "--out",
          out.string(),
          "--ladder",
          "--set",
          "splits.min_block_coverage=0",
          "--set",
          "crops.min_lidar_coverage=0.01",
          "--set",
          "splits.ratios={\"train\": 0, \"val\": 0, \"test\": 1}"};
}

fs::path e2e_ladder_dataset() {
  const fs::path config = source_dir() / "tests/data/generate/e2e.json";
  return cached_folder("dataset_e2e_ladder", nsgraph_build_key() + "-" + content_key(config), [&](const fs::path& dir) {
    std::vector<std::string> args = e2e_ladder_args(dir);
    args.insert(args.end(), {"--threads", "2"});
    const CommandResult r = run_nsgraph(args);
    if (r.exit_code != 0) throw std::runtime_error("generate e2e --ladder failed: " + r.err);
  });
}

nlohmann::json read_json(const fs::path& path) { return nlohmann::json::parse(read_file(path)); }

std::map<std::string, std::string> scene_dates(const fs::path& release) {
  std::map<std::string, std::string> log_date, out;
  for (const nlohmann::json& l : read_json(release / "v1.0-mini" / "log.json"))
    log_date[l["token"]] = l["date_captured"];
  for (const nlohmann::json& s : read_json(release / "v1.0-mini" / "scene.json"))
    out[s["name"]] = log_date.at(s["log_token"]);
  return out;
}

void export_real_keyframe_frames(const fs::path& release, const fs::path& dir) {
  const CommandResult g = run_nsgraph({"generate", "--quiet", "--config",
                                       (source_dir() / "tests/data/frames/real-keyframe-generate.json").string(),
                                       "--dataroot", release.string(), "--version", "v1.0-mini", "--no-semantic",
                                       "--allow-empty", "--out", (dir / "dataset").string()});
  if (g.exit_code != 0) throw std::runtime_error("generate of the real key frame failed: " + g.err);
  const CommandResult f =
      run_nsgraph({"frames", "--quiet", "--dataset", (dir / "dataset").string(), "--out", (dir / "frames").string()});
  if (f.exit_code != 0) throw std::runtime_error("frames of the real key frame failed: " + f.err);
}

std::vector<std::pair<std::string, std::string>> tree_hashes(const fs::path& dir) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), dir).generic_string();
    if (rel.rfind("parts/", 0) == 0) continue;
    if (rel == "manifest.json") {
      // inputs.dataroot is relative to the dataset's folder: datasets in other folders write
      // another path to the same release. Compared as the folder it resolves to.
      nlohmann::ordered_json m = nlohmann::ordered_json::parse(read_file(e.path()));
      m["inputs"]["dataroot"] = resolve_document_path(m["inputs"]["dataroot"].get<std::string>(), dir).string();
      out.emplace_back(rel, sha256_hex(m.dump(1)));
      continue;
    }
    out.emplace_back(rel, sha256_file(e.path()));
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace nsg::test
