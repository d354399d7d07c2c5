// Score reports and receipts from a stranger (metrics::read_receipt, the one reader that
// `score --verify-receipt` and the leaderboard use): any bytes are either refused by name
// (the submission limits on the file, then a ParseError or ConfigError naming the field) or
// read into a receipt whose digests are 64 hex digits, sizes >= 0, limits and metric
// parameters within their documented ranges; results_sha256 of any parsed document works.
#include <cstdlib>
#include <optional>

#include "fuzz_support.h"
#include "nsg/core/issues.h"
#include "nsg/metrics/receipt.h"
#include "nsg/validate/submission.h"

namespace {

bool is_digest(const std::string& s) {
  return s.size() == 64 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = nsg::fuzz::input_file(data, size);
  nsg::Issues issues;
  const std::optional<nlohmann::json> doc =
      nsg::validate::read_submission(file, nsg::validate::SubmissionLimits{}, issues);
  if (!doc) return 0;
  (void)nsg::metrics::results_sha256(*doc);
  std::optional<nsg::metrics::Receipt> r;
  nsg::fuzz::expect_only_input_errors([&] { r = nsg::metrics::read_receipt(*doc, file.string()); });
  if (!r) return 0;
  if (!is_digest(r->ground_truth_sha256) || !is_digest(r->submission_sha256) || !is_digest(r->results_sha256))
    std::abort();
  if (r->submission_bytes < 0) std::abort();
  try {  // the reader let nothing outside the documented ranges through
    r->params.validate();
    r->limits.validate();
  } catch (...) {
    std::abort();
  }
  return 0;
}
