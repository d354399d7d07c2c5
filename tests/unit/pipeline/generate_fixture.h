#pragma once
// The synthetic release of tests/data/synth/e2e.json and its dataset from
// tests/data/generate/e2e.json, made once per build and shared by the test processes.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::test {

std::filesystem::path e2e_release();
// The dataset generated with 2 threads in one process.
std::filesystem::path e2e_dataset();
std::vector<std::string> e2e_generate_args(const std::filesystem::path& out);
nlohmann::json read_json(const std::filesystem::path& path);
// sha256 of every file under `dir` except parts/ (the run's bookkeeping), by relative path.
std::vector<std::pair<std::string, std::string>> tree_hashes(const std::filesystem::path& dir);

}  // namespace nsg::test
