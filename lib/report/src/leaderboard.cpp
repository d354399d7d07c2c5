// write_leaderboard: score reports from a folder, checked against their receipts and
// against one ground truth, into a static sortable page (report.h).
#include <algorithm>

#include "internal.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/strings.h"
#include "nsg/core/version.h"
#include "nsg/metrics/receipt.h"
#include "nsg/validate/submission.h"

namespace nsg::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

constexpr const char* kMarker = "leaderboard.json";  // what makes a folder an earlier leaderboard

// The table's metric columns are the headline metrics' aggregate means (metrics::headline_metrics).

// A report from the folder, read as a stranger's file (bounded like a submission).
json read_report(const fs::path& file, std::string* why) {
  Issues issues;
  std::optional<json> doc = validate::read_submission(file, validate::SubmissionLimits{}, issues);
  if (!doc) {
    *why = issues.items().front().message;
    return nullptr;
  }
  return std::move(*doc);
}

// The page's entry of an accepted report and its receipt; "" in `why` when it is accepted.
// Every field is read through a typed reader (metrics::read_receipt) or checked for its
// type here, so a mistyped report is rejected with its reason, never an internal error.
ordered_json entry_of(const fs::path& file, const json& report, metrics::Receipt* receipt, std::string* why) {
  why->clear();
  try {
    *receipt = metrics::read_receipt(report, file.string());
    NSG_CHECK(report.contains("aggregate") && report["aggregate"].is_object() && report["aggregate"].contains("mean") &&
                  report["aggregate"]["mean"].is_object(),
              ParseError, file.string(), "/aggregate", "a score report's aggregate (a receipt alone has no numbers)");
    if (metrics::results_sha256(report) != receipt->results_sha256) {
      *why = "its numbers do not hash to its receipt's results_sha256 (changed after scoring)";
      return nullptr;
    }
    const json& agg = report["aggregate"];
    ordered_json values = ordered_json::object();
    for (const metrics::HeadlineMetric& h : metrics::headline_metrics()) {
      const char* name = metrics::metric_name(h.metric);
      const json v = agg["mean"].contains(name) ? agg["mean"][name] : json();
      values[name] = v.is_number() ? v : json();
    }
    const auto count = [&](const char* name) {
      return agg.contains(name) && agg[name].is_number_integer() ? agg[name] : json();
    };
    return {{"name", file.stem().string()},
            {"file", file.filename().string()},
            {"values", values},
            {"n_tiles", count("n_tiles")},
            {"n_missing_predictions", count("n_missing_predictions")},
            {"submission_sha256", receipt->submission_sha256},
            {"results_sha256", receipt->results_sha256},
            {"toolkit", "nsgraph " + receipt->toolkit_version + " (" + receipt->toolkit_commit.substr(0, 12) + ")"}};
  } catch (const Error& e) {
    *why = e.what();
  }
  return nullptr;
}

ordered_json columns_json() {
  ordered_json out = ordered_json::array();
  for (const metrics::HeadlineMetric& h : metrics::headline_metrics())
    out.push_back({{"name", metrics::metric_name(h.metric)},
                   {"label", h.label},
                   {"better", metrics::metric_info(h.metric).lower_is_better ? "lower" : "higher"},
                   {"digits", h.digits}});
  return out;
}

}  // namespace

LeaderboardResult write_leaderboard(const fs::path& reports, const fs::path& out) {
  NSG_CHECK(fs::is_directory(reports), IoError, reports.string(), "--leaderboard", "a folder of score reports");
  refuse_out_over_input(out, reports, "--leaderboard");
  detail::check_replaceable(out, kMarker, "--out");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(reports))
    if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());

  LeaderboardResult result;
  ordered_json entries = ordered_json::array(), rejected = ordered_json::array();
  json reference_gt;      // the first accepted receipt's ground truth
  std::string reference;  // its identity
  const auto reject = [&](const fs::path& file, const std::string& why) {
    rejected.push_back({{"file", file.filename().string()}, {"reason", why}});
    result.rejected.push_back(file.string() + ": " + why);
  };
  for (const fs::path& file : files) {
    std::string why;
    const json report = read_report(file, &why);
    if (report.is_null()) {
      reject(file, why);
      continue;
    }
    metrics::Receipt receipt;
    ordered_json entry = entry_of(file, report, &receipt, &why);
    if (entry.is_null()) {
      reject(file, why);
      continue;
    }
    const std::string identity = receipt.ground_truth_identity();
    if (reference.empty()) {
      reference = identity;
      reference_gt = metrics::receipt_of(report, file.string())["ground_truth"];
    } else if (identity != reference) {
      reject(file,
             "its receipt names another ground truth (" + identity + ") than the first report's (" + reference + ")");
      continue;
    }
    entries.push_back(std::move(entry));
  }
  NSG_CHECK(!entries.empty(), DataError, reports.string(), "--leaderboard",
            "at least one score report with a valid receipt (" + std::to_string(files.size()) + " *.json file(s), " +
                std::to_string(rejected.size()) + " rejected)");
  result.entries = static_cast<int64_t>(entries.size());

  const ordered_json doc = {{"format", "nsgraph-leaderboard-1"},
                            {"tool", std::string("nsgraph ") + kVersion},
                            {"ground_truth", reference_gt},
                            {"metrics_version", metrics::kMetricsVersion},
                            {"columns", columns_json()},
                            {"entries", entries},
                            {"rejected", rejected}};
  const fs::path parent = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  fs::create_directories(parent);
  detail::TempFolder tmp{temp_path_for(out)};
  fs::create_directories(tmp.path / "data");
  const std::string prefix = detail::kLeaderboardAssets;
  for (const detail::Asset& a : detail::assets())
    if (starts_with(a.name, prefix)) detail::write_text(tmp.path / std::string(a.name).substr(prefix.size()), a.bytes);
  // ASCII only: file names may hold any bytes.
  const std::string text = doc.dump(-1, ' ', true, json::error_handler_t::replace);
  detail::write_text(tmp.path / "data" / "leaderboard.js", detail::data_script("leaderboard", text));
  detail::write_marker(tmp.path, kMarker, doc);
  detail::replace_folder(tmp.path, out, kMarker);
  tmp.keep = true;
  return result;
}

}  // namespace nsg::report
