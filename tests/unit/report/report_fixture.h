#pragma once
// Inputs of the report tests: the e2e dataset and submissions made from its ground truth
// with known defects, and reading the report's data files back.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::test {

// What the perturbed submission did to which tile.
struct PerturbedSubmission {
  std::filesystem::path file;
  std::string dropped;   // a test tile with edges left out (missing prediction)
  std::string reversed;  // a test tile whose every edge points the other way
  int reversed_edges = 0;
};
// The test split's ground truth as a submission, except one tile dropped and one reversed.
PerturbedSubmission perturbed_submission(const std::filesystem::path& dir);
// The ground truth of the test split as a submission (a perfect score).
std::filesystem::path exact_submission(const std::filesystem::path& dir);
// A submission of e2e_ladder_dataset's test tiles with known answers per rung: the exact
// graph at "all", -r2 and -r4, an empty one at -r1 (dir/ladder-sub.json).
std::filesystem::path ladder_submission(const std::filesystem::path& dir);
// A folder of score reports (nsgraph score --out) on the e2e dataset's test split:
// exact.json (perfect), perturbed.json and empty.json (every tile an empty graph).
std::filesystem::path leaderboard_reports(const std::filesystem::path& dir);
// The entry names of a leaderboard.json sorted as the page sorts by `column`: better first
// (or `dir` "asc" / "desc"), undefined last, ties by name.
std::vector<std::string> leaderboard_order(const nlohmann::json& board, const std::string& column,
                                           const std::string& dir = "");
// The JSON inside a data file `NSG.receive("name", {...});`.
nlohmann::json read_data_script(const std::filesystem::path& file);

}  // namespace nsg::test
