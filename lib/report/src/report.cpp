// write_report: score (when there is a submission), one pass over the tiles, the
// documents and the static page, all in a temp folder renamed over `out` at the end.
#include <fstream>
#include <system_error>

#include "internal.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
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

void replace_folder(const fs::path& tmp, const fs::path& out) {
  std::error_code ec;
  if (!fs::exists(out)) {
    fs::rename(tmp, out, ec);
    NSG_CHECK(!ec, IoError, out.string(), "", "a folder the report can be renamed to (" + ec.message() + ")");
    return;
  }
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

using detail::folder_bytes;
using detail::replace_folder;
using detail::TempFolder;
using detail::write_text;

void ReportOptions::validate() const {
  NSG_CHECK(threads >= 0 && threads <= 1024, ConfigError, "", "--threads", "0 (all cores) … 1024");
  NSG_CHECK(baseline.empty() || !submission.empty(), ConfigError, "", "--baseline",
            "a --submission to compare the baseline with");
  NSG_CHECK(overview_max_px >= 64 && overview_max_px <= 16384, ConfigError, "", "overview_max_px", "64 … 16384");
}

ReportResult write_report(const fs::path& dataset_root, const fs::path& out, const ReportOptions& options) {
  options.validate();
  NSG_CHECK(!out.empty(), ConfigError, "", "--out", "an output folder");
  if (fs::exists(out)) {
    const bool empty_dir = fs::is_directory(out) && fs::is_empty(out);
    NSG_CHECK(empty_dir || fs::exists(out / kMarker), ConfigError, out.string(), "--out",
              "a new folder, an empty one or an earlier report (it holds other files; not overwritten)");
  }
  const io::Dataset dataset = io::Dataset::open(dataset_root);
  const bool scored = !options.submission.empty();
  // With a submission and no split: the split its keys are tiles of (score_submission).
  std::string split = options.split;

  ReportResult result;
  metrics::ScoredSubmission sub, base;
  metrics::SubmissionScoreOptions scoring;
  scoring.split = split;
  scoring.schemas_dir = options.schemas;
  scoring.score.threads = options.threads;
  const metrics::ScoreSource truth = metrics::ScoreSource::file(dataset_root);
  if (scored) {
    log::info("report: scoring " + options.submission.string());
    sub = metrics::score_submission(truth, metrics::ScoreSource::file(options.submission), scoring);
    if (!sub.issues.empty()) {
      result.issues = std::move(sub.issues);
      result.rejected = options.submission.string();
      return result;
    }
    split = sub.report.split;
    scoring.split = split;  // the baseline is scored on the submission's split
    if (!options.baseline.empty()) {
      log::info("report: scoring the baseline " + options.baseline.string());
      base = metrics::score_submission(truth, metrics::ScoreSource::file(options.baseline), scoring);
      if (!base.issues.empty()) {
        result.issues = std::move(base.issues);
        result.rejected = options.baseline.string();
        return result;
      }
    }
  }
  const bool with_baseline = scored && !options.baseline.empty();
  // An earlier report at `out` lends the images of tiles that did not change.
  const detail::EarlierImages earlier =
      fs::exists(out / kMarker) ? detail::earlier_images(out) : detail::EarlierImages{};

  fs::path parent = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  fs::create_directories(parent);
  TempFolder tmp{temp_path_for(out)};
  fs::create_directories(tmp.path);

  detail::TileInputs inputs;
  if (scored) {
    inputs.prediction = &sub.graphs;
    inputs.scores = &sub.report;
    if (with_baseline) {
      inputs.baseline = &base.report;
      inputs.baseline_prediction = &base.graphs;
    }
  }
  log::info("report: rendering the tiles of " + (split.empty() ? std::string("every split") : "split " + split));
  const detail::TilePass pass =
      detail::write_tile_pages(dataset, split, inputs, earlier, tmp.path, options.threads, options.progress);
  NSG_CHECK(!pass.rows.empty(), DataError, (dataset_root / "manifest.json").string(), split.empty() ? "shards" : split,
            "at least one tile to report");

  nlohmann::ordered_json summary =
      detail::summary_document(dataset, split, scored ? &sub.report : nullptr, with_baseline ? &base.report : nullptr);
  const nlohmann::ordered_json overviews =
      detail::write_overviews(dataset, split, pass.rows, tmp.path, options.overview_max_px);
  for (auto& loc : summary["locations"])
    if (overviews.contains(loc["name"].get<std::string>())) loc["overview"] = overviews[loc["name"].get<std::string>()];
  summary["n_tiles"] = pass.rows.size();

  const std::vector<std::string> columns = detail::table_columns(scored, with_baseline);
  write_text(tmp.path / "data" / "summary.js", detail::data_script("summary", summary.dump()));
  write_text(tmp.path / "data" / "tiles.js",
             detail::data_script("tiles", detail::tiles_document(pass.rows, columns).dump()));
  for (const detail::Asset& a : detail::assets())
    if (!starts_with(a.name, detail::kLeaderboardAssets)) write_text(tmp.path / a.name, a.bytes);
  write_text(tmp.path / kMarker, summary.dump(1) + "\n");

  result.tiles = static_cast<int64_t>(pass.rows.size());
  result.images = pass.images + static_cast<int64_t>(overviews.size());
  result.images_reused = pass.images_reused;
  result.bytes = folder_bytes(tmp.path);
  replace_folder(tmp.path, out);
  tmp.keep = true;
  return result;
}

}  // namespace nsg::report
