#pragma once
// The submission limits as `score` and `validate --submission` take them: one flag set,
// declared once, so a file one accepts the other accepts (docs/scoring-limits.md).
#include <CLI/CLI.hpp>
#include <string>

#include "nsg/validate/submission.h"

namespace nsg::cli {

// --max-file-mb: the file or stream limit, and the JSON value limit in proportion (a
// larger split's submission holds more values per file, never more per tile). The
// per-tile limits are the metric's time bound and part of the benchmark: no flag.
void add_submission_limit_flags(CLI::App* cmd, validate::SubmissionLimits& limits);

// The --help footer listing the limits in force.
std::string submission_limits_footer(const validate::SubmissionLimits& limits);

}  // namespace nsg::cli
