#pragma once
// The synthetic release of tests/data/synth/e2e.json and its dataset from
// tests/data/generate/e2e.json, made once per build and shared by the test processes.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::test {

std::filesystem::path e2e_release();
// A view of `release` (symlinks to its files) whose scene table has scene `from` renamed
// to `to`, written under `dir`; returns the view's root.
std::filesystem::path release_with_renamed_scene(const std::filesystem::path& release, const std::string& version,
                                                 const std::string& from, const std::string& to,
                                                 const std::filesystem::path& dir);
// The dataset generated with 2 threads in one process.
std::filesystem::path e2e_dataset();
std::vector<std::string> e2e_generate_args(const std::filesystem::path& out);
// e2e_generate_args with an observation ladder (--ladder: rungs 1, 2 and 4 of the test split)
// and 3 tiles a shard (so a split has several rung shards).
std::vector<std::string> e2e_ladder_args(const std::filesystem::path& out);
// generate --ladder on the real key frame (tests/data/real/scene-0061-keyframe: one scene,
// one sweep) into `out`, with the sparse-data settings its crops need, every tile to test.
std::vector<std::string> real_keyframe_ladder_args(const std::filesystem::path& out);
// The dataset of e2e_ladder_args with 2 threads, built once per build and config like
// e2e_dataset.
std::filesystem::path e2e_ladder_dataset();
nlohmann::json read_json(const std::filesystem::path& path);
// sha256 of every file under `dir` except parts/ (the run's bookkeeping), by relative path;
// the manifest's inputs.dataroot counts as the folder it names (it is relative to `dir`).
std::vector<std::pair<std::string, std::string>> tree_hashes(const std::filesystem::path& dir);
// scene name → its log's date_captured, from a release's tables.
std::map<std::string, std::string> scene_dates(const std::filesystem::path& release);
// The real key frame's release (`release`: the repository's copy, or one with another map)
// generated with tests/data/frames/real-keyframe-generate.json into dir/dataset and exported
// by `nsgraph frames` into dir/frames; a failed step fails the test.
void export_real_keyframe_frames(const std::filesystem::path& release, const std::filesystem::path& dir);

}  // namespace nsg::test
