// The submission reader (read_submission) and the structural checks that follow it in
// `validate --submission` and `score`.
#include "fuzz_support.h"
#include "nsg/validate/submission.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = nsg::fuzz::input_file(data, size);
  nsg::fuzz::expect_only_input_errors([&] {
    nsg::validate::SubmissionLimits limits;
    limits.max_file_bytes = 1 << 20;  // keep each input cheap
    nsg::Issues issues;
    const std::optional<nlohmann::json> doc = nsg::validate::read_submission(file, limits, issues);
    if (doc) (void)nsg::validate::check_submission_structure(*doc, "submission.json", limits);
  });
  return 0;
}
