#pragma once
// simdjson's DOM for the frame documents (results files reach 128 MiB; nlohmann parses
// them at ~30 MB/s, simdjson at GB/s), with the strict rules of a stranger's file:
// nesting and value count bounded, no key twice in an object (JSON leaves its meaning
// open), NaN/Infinity refused (they are not JSON).
#include <cstdint>
#include <optional>
#include <string>

#include <simdjson.h>

#include "nsg/core/issues.h"
#include "nsg/metrics/frames.h"

namespace nsg::metrics::detail {

// Parses `text` into `doc` with `parser` and checks the strict rules; false with the problem
// in `issues` (checks submission.json, submission.size; subject "<label>:<pointer>").
bool parse_strict(simdjson::dom::parser& parser, const simdjson::padded_string& text, const std::string& label,
                  int max_depth, int64_t max_values, simdjson::dom::element& doc, Issues& issues);

// A number of any JSON kind as a double (integers converted), or nullopt.
std::optional<double> number(simdjson::dom::element e);

}  // namespace nsg::metrics::detail
