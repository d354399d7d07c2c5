// write_report: score (when there is a submission), one pass over the tiles, the
// documents and the static page, all in a temp folder renamed over `out` at the end.
#include <algorithm>
#include <fstream>
#include <set>
#include <system_error>

#include "internal.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/files.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/score_submission.h"

namespace nsg::report {
namespace {

namespace fs = std::filesystem;

constexpr const char* kMarker = "report.json";  // what makes a folder an earlier report

}  // namespace

namespace detail {

void write_text(const fs::path& path, std::string_view text) {
  std::ofstream f(path, std::ios::binary);
  f.write(text.data(), static_cast<std::streamsize>(text.size()));
  f.close();
  NSG_CHECK(f.good(), IoError, path.string(), "", "a writable file (disk full?)");
}

int64_t folder_bytes(const fs::path& dir) {
  int64_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) n += static_cast<int64_t>(e.file_size());
  return n;
}

void write_marker(const fs::path& dir, const char* marker, nlohmann::ordered_json doc) {
  std::vector<std::string> files = OutputFolder(dir).files_under({"."});
  files.push_back(marker);
  std::sort(files.begin(), files.end());
  doc["files"] = files;
  write_text(dir / marker, doc.dump(1, ' ', true, nlohmann::json::error_handler_t::replace) + "\n");
}

void check_replaceable(const fs::path& out, const char* marker, const std::string& option) {
  NSG_CHECK(!out.empty(), ConfigError, "", option, "an output folder");
  std::error_code ec;
  if (!fs::exists(out, ec)) return;
  NSG_CHECK(fs::is_directory(out, ec), ConfigError, out.string(), option, "a folder (it is a file)");
  if (fs::is_empty(out, ec)) return;
  const fs::path file = out / marker;
  NSG_CHECK(fs::is_regular_file(fs::symlink_status(file, ec)), ConfigError, out.string(), option,
            std::string("a new folder, an empty one or an earlier page of ours (it holds other files and no ") +
                marker + "; not overwritten)");
  std::set<std::string> listed = {marker};
  try {
    const nlohmann::json doc = nlohmann::json::parse(read_file(file));
    for (const auto& f : doc.at("files"))
      if (f.is_string()) listed.insert(f.get<std::string>());
  } catch (const std::exception&) {
    // Unreadable or without a listing (an older nsgraph's): only the marker is ours.
  }
  OutputFolder(out, option).refuse_unlisted(listed, {"."}, std::string("the earlier page's ") + marker);
}

void replace_folder(const fs::path& tmp, const fs::path& out, const char* marker) {
  std::error_code ec;
  if (!fs::exists(out)) {
    fs::rename(tmp, out, ec);
    NSG_CHECK(!ec, IoError, out.string(), "", "a folder the report can be renamed to (" + ec.message() + ")");
    return;
  }
  check_replaceable(out, marker, "--out");  // again: a file may have been added while we rendered
  const fs::path old = temp_path_for(out);
  fs::rename(out, old, ec);
  NSG_CHECK(!ec, IoError, out.string(), "", "an earlier report that can be moved aside (" + ec.message() + ")");
  fs::rename(tmp, out, ec);
  if (ec) {
    std::error_code back;
    fs::rename(old, out, back);
    throw IoError(out.string(), "", "a folder the report can be renamed to (" + ec.message() + ")");
  }
  fs::remove_all(old, ec);
}

}  // namespace detail

using detail::check_replaceable;
using detail::folder_bytes;
using detail::replace_folder;
using detail::TempFolder;
using detail::write_marker;
using detail::write_text;

void ReportOptions::validate() const {
  NSG_CHECK(threads >= 0 && threads <= 1024, ConfigError, "", "--threads", "0 (all cores) … 1024");
  NSG_CHECK(baseline.empty() || !submission.empty(), ConfigError, "", "--baseline",
            "a --submission to compare the baseline with");
  NSG_CHECK(overview_max_px >= 64 && overview_max_px <= 16384, ConfigError, "", "overview_max_px", "64 … 16384");
}

namespace {

// Scores the submission and then the baseline, on the submission's split (which becomes
// `split`). False, with the refused file and its issues in `result`, when either is refused.
bool score_submissions(const fs::path& dataset_root, const ReportOptions& options, std::string& split,
                       metrics::ScoredSubmission& sub, metrics::ScoredSubmission& base, ReportResult& result) {
  metrics::SubmissionScoreOptions scoring;
  scoring.split = split;
  scoring.schemas_dir = options.schemas;
  scoring.score.threads = options.threads;
  const metrics::ScoreSource truth = metrics::ScoreSource::file(dataset_root);
  log::info("report: scoring " + options.submission.string());
  sub = metrics::score_submission(truth, metrics::ScoreSource::file(options.submission), scoring);
  if (!sub.issues.empty()) {
    result.issues = std::move(sub.issues);
    result.rejected = options.submission.string();
    return false;
  }
  split = sub.report.split;
  scoring.split = split;  // the baseline is scored on the submission's split
  if (!options.baseline.empty()) {
    log::info("report: scoring the baseline " + options.baseline.string());
    base = metrics::score_submission(truth, metrics::ScoreSource::file(options.baseline), scoring);
    if (!base.issues.empty()) {
      result.issues = std::move(base.issues);
      result.rejected = options.baseline.string();
      return false;
    }
  }
  return true;
}

detail::TileInputs tile_inputs(bool scored, bool with_baseline, const metrics::ScoredSubmission& sub,
                               const metrics::ScoredSubmission& base) {
  detail::TileInputs inputs;
  if (scored) {
    inputs.prediction = &sub.graphs;
    inputs.scores = &sub.report;
    inputs.rung_scores = &sub.rung_reports;
    if (with_baseline) {
      inputs.baseline = &base.report;
      inputs.baseline_prediction = &base.graphs;
    }
  }
  return inputs;
}

// The summary document, each location with its overview image (written into `dir`);
// `n_overviews` is how many were written.
nlohmann::ordered_json summary_with_overviews(const io::Dataset& dataset, const std::string& split,
                                              const metrics::ScoreReport* scores, const metrics::ScoreReport* baseline,
                                              const std::vector<detail::TileRow>& rows, const fs::path& dir,
                                              int overview_max_px, int64_t* n_overviews) {
  nlohmann::ordered_json summary = detail::summary_document(dataset, split, scores, baseline);
  const nlohmann::ordered_json overviews = detail::write_overviews(dataset, split, rows, dir, overview_max_px);
  for (auto& loc : summary["locations"])
    if (overviews.contains(loc["name"].get<std::string>())) loc["overview"] = overviews[loc["name"].get<std::string>()];
  summary["n_tiles"] = rows.size();
  *n_overviews = static_cast<int64_t>(overviews.size());
  return summary;
}

// The page's data scripts, its static assets and the marker of a report folder.
void write_page(const fs::path& dir, const nlohmann::ordered_json& summary, const std::vector<detail::TileRow>& rows,
                bool scored, bool with_baseline) {
  const std::vector<std::string> columns = detail::table_columns(scored, with_baseline);
  write_text(dir / "data" / "summary.js", detail::data_script("summary", summary.dump()));
  write_text(dir / "data" / "tiles.js", detail::data_script("tiles", detail::tiles_document(rows, columns).dump()));
  for (const detail::Asset& a : detail::assets())
    if (!starts_with(a.name, detail::kLeaderboardAssets)) write_text(dir / a.name, a.bytes);
  write_marker(dir, kMarker, summary);
}

}  // namespace

ReportResult write_report(const fs::path& dataset_root, const fs::path& out, const ReportOptions& options) {
  options.validate();
  refuse_out_over_input(out, dataset_root, "--dataset");
  for (const fs::path& input : {options.submission, options.baseline})
    refuse_out_over_input(out, input, "--submission");
  check_replaceable(out, kMarker, "--out");
  const io::Dataset dataset = io::Dataset::open(dataset_root);
  const bool scored = !options.submission.empty();
  // With a submission and no split: the split its keys are tiles of (score_submission).
  std::string split = options.split;

  ReportResult result;
  metrics::ScoredSubmission sub, base;
  if (scored && !score_submissions(dataset_root, options, split, sub, base, result)) return result;
  const bool with_baseline = scored && !options.baseline.empty();
  // An earlier report at `out` lends the images of tiles that did not change.
  const detail::EarlierImages earlier =
      fs::exists(out / kMarker) ? detail::earlier_images(out) : detail::EarlierImages{};

  fs::path parent = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  fs::create_directories(parent);
  TempFolder tmp{temp_path_for(out)};
  fs::create_directories(tmp.path);

  log::info("report: rendering the tiles of " + (split.empty() ? std::string("every split") : "split " + split));
  const detail::TilePass pass = detail::write_tile_pages(dataset, split, tile_inputs(scored, with_baseline, sub, base),
                                                         earlier, tmp.path, options.threads, options.progress);
  NSG_CHECK(!pass.rows.empty(), DataError, (dataset_root / "manifest.json").string(), split.empty() ? "shards" : split,
            "at least one tile to report");

  int64_t n_overviews = 0;
  const nlohmann::ordered_json summary =
      summary_with_overviews(dataset, split, scored ? &sub.report : nullptr, with_baseline ? &base.report : nullptr,
                             pass.rows, tmp.path, options.overview_max_px, &n_overviews);
  write_page(tmp.path, summary, pass.rows, scored, with_baseline);

  result.tiles = static_cast<int64_t>(pass.rows.size());
  result.images = pass.images + n_overviews;
  result.images_reused = pass.images_reused;
  result.bytes = folder_bytes(tmp.path);
  replace_folder(tmp.path, out, kMarker);
  tmp.keep = true;
  return result;
}

}  // namespace nsg::report
