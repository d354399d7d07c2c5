#pragma once
// The synthetic release of tests/data/synth/e2e.json and its dataset from
// tests/data/generate/e2e.json, made once per build and shared by the test processes.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::test {

std::filesystem::path e2e_release();
// samples/synth/tiny.json synthesized with seed 7 (one small block: the default config
// plans no tile on it).
std::filesystem::path tiny_release();
// A view of `release` (symlinks to its files) whose scene table has scene `from` renamed
// to `to`, written under `dir`; returns the view's root.
std::filesystem::path release_with_renamed_scene(const std::filesystem::path& release, const std::string& version,
                                                 const std::string& from, const std::string& to,
                                                 const std::filesystem::path& dir);
// The dataset generated with 2 threads in one process.
std::filesystem::path e2e_dataset();
// The e2e dataset with an observation ladder (generate --ladder: rungs 1, 2 and 4 of the test
// split), built once per build and config like e2e_dataset.
std::filesystem::path e2e_ladder_dataset();
std::vector<std::string> e2e_generate_args(const std::filesystem::path& out);
nlohmann::json read_json(const std::filesystem::path& path);
// sha256 of every file under `dir` except parts/ (the run's bookkeeping), by relative path.
std::vector<std::pair<std::string, std::string>> tree_hashes(const std::filesystem::path& dir);

}  // namespace nsg::test
