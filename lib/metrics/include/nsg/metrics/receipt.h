#pragma once
// Score receipts (docs/metrics.md "Receipts"). The ground truth is public — anyone can
// generate it from the map — so a score is made verifiable instead of secret: the report
// records what it was computed from (the dataset's manifest digest, which pins every
// shard's sha256, and the submission's bytes), with what (toolkit version and commit,
// metrics version, limits, options), and a digest of its numbers. Anyone holding the same
// dataset and submission recomputes and compares.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/metrics/params.h"
#include "nsg/metrics/score.h"
#include "nsg/validate/submission.h"

namespace nsg::metrics {

// What the receipt records of the inputs (filled by score_submission).
struct ReceiptInputs {
  std::string ground_truth_kind;    // "dataset", "file" or "memory"
  std::string ground_truth_sha256;  // of manifest.json (dataset) or of the bytes (file, memory)
  std::string split;                // the dataset split scored
  std::string verification;         // ScoreReport::ground_truth_verification
  std::string submission_sha256;    // of the bytes scored
  int64_t submission_bytes = 0;
  bool verify_ground_truth = true;
};

// The receipt of `report` (schemas/v1/score-report.schema.json, /receipt).
nlohmann::json make_receipt(const ScoreReport& report, const ReceiptInputs& inputs,
                            const validate::SubmissionLimits& limits);

// The digest of a report's numbers: sha256 of the compact JSON of its params, missing and
// extra keys, tiles and aggregate (sorted keys, shortest round-trip doubles), so a report
// read back from its file hashes as it did when written.
std::string results_sha256(const nlohmann::json& report);

// A receipt as a typed document: the one reader of a receipt (score --verify-receipt, the
// leaderboard) checks every field's presence, type and range, so no stranger's receipt
// reaches the code that uses it mistyped.
struct Receipt {
  std::string ground_truth_kind;    // "dataset", "file" or "memory"
  std::string ground_truth_sha256;  // manifest_sha256 (dataset) or sha256 (file, memory)
  std::string split;                // ground_truth.split (dataset; "" otherwise)
  std::string verification;         // "sha256", "sizes", "file" or "memory"
  std::string submission_sha256;
  int64_t submission_bytes = 0;
  std::string toolkit_version, toolkit_commit;
  std::string metrics_version;
  validate::SubmissionLimits limits;  // what the scorer that wrote it enforced
  MetricParams params;                // options.params, within the documented ranges
  std::string options_split;          // options.split
  bool verify_ground_truth = true;    // options.verify_ground_truth
  std::string results_sha256;

  // "<kind> <sha256> <split> metrics v<version>": receipts of one ground truth share it.
  std::string ground_truth_identity() const;
};
// Reads the receipt of `doc` — a score report carrying one, or a receipt alone — from a
// stranger: ParseError naming `file` and the JSON pointer of the first field missing or of
// the wrong type, ConfigError when a limit or option is outside its documented range.
Receipt read_receipt(const nlohmann::json& doc, const std::string& file);
// The receipt object of `doc` (a report's /receipt, or `doc` itself).
const nlohmann::json& receipt_of(const nlohmann::json& doc, const std::string& file);

struct ReceiptComparison {
  std::vector<std::string> differences;  // each a line: what, recorded, recomputed
  std::vector<std::string> notes;        // differences that change no number (toolkit build)
  bool same() const { return differences.empty(); }
};
// Compares a recorded report or receipt (read_receipt has accepted it) with a recomputed
// report, which carries its own receipt. Receipts verify, never configure: the recomputed
// report was scored with the verifier's own options and limits, so a recorded receipt
// with other options differs here, whatever numbers it claims. The inputs, options and
// metrics version must be equal (other limits, verification or toolkit are notes: they
// change no number of an accepted submission); the numbers must hash the same, or — where
// the recorded document is a whole report — every per-tile and aggregate value must agree
// within 1e-9 (another CPU or compiler may move the last bits; a note says so). A recorded
// report whose own numbers no longer hash to its receipt is a difference (edited after
// scoring).
ReceiptComparison compare_receipt(const nlohmann::json& recorded, const nlohmann::json& recomputed,
                                  const std::string& file);

}  // namespace nsg::metrics
