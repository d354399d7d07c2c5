#pragma once
// Reading JSON that comes from outside (submissions, dataset members, manifests): nesting
// is capped, so nothing downstream recurses on an attacker's depth, and a key repeated
// within one object is an error (JSON leaves it undefined; nlohmann keeps the last, so a
// duplicated key could silently replace a value).
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "nsg/core/strings.h"  // printable_utf8

namespace nsg {

inline constexpr int kMaxJsonDepth = 64;  // our formats nest at most 6 deep

// Parses `text`; ParseError naming `label` and the byte (invalid JSON), the repeated key,
// or the nesting depth. `what` says what the document should be ("the dataset manifest").
nlohmann::json parse_json_strict(std::string_view text, const std::string& label, const std::string& what = "",
                                 int max_depth = kMaxJsonDepth);

}  // namespace nsg
