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

// What to recompute a receipt with.
struct ReceiptRecipe {
  MetricParams params;
  std::string split;
  bool verify_ground_truth = true;
  validate::SubmissionLimits limits;
};
// Reads `doc` — a score report carrying a receipt, or a receipt alone — from a stranger:
// throws ParseError naming `file` and the field when a field is missing or of the wrong
// type, ConfigError when the options or limits are out of range.
ReceiptRecipe receipt_recipe(const nlohmann::json& doc, const std::string& file);
// The receipt object of `doc` (a report's /receipt, or `doc` itself).
const nlohmann::json& receipt_of(const nlohmann::json& doc, const std::string& file);

struct ReceiptComparison {
  std::vector<std::string> differences;  // each a line: what, recorded, recomputed
  std::vector<std::string> notes;        // differences that change no number (toolkit build)
  bool same() const { return differences.empty(); }
};
// Compares a recorded report or receipt with a recomputed report (which carries its own
// receipt). The inputs, options, limits and metrics version must be equal; the numbers
// must hash the same, or — where the recorded document is a whole report — every
// aggregate value must agree within 1e-9 (another CPU or compiler may move the last bits
// of a tile's value; a note says so). A recorded report whose own numbers no longer hash
// to its receipt is a difference (edited after scoring).
ReceiptComparison compare_receipt(const nlohmann::json& recorded, const nlohmann::json& recomputed,
                                  const std::string& file);

}  // namespace nsg::metrics
