#pragma once
// Small string helpers.
#include <string>
#include <string_view>
#include <vector>

namespace nsg {

std::vector<std::string> split(std::string_view text, char sep);
std::string join(const std::vector<std::string>& parts, std::string_view sep);
std::string_view trim(std::string_view text);
bool starts_with(std::string_view text, std::string_view prefix);
bool ends_with(std::string_view text, std::string_view suffix);
// Shortest decimal that round-trips to the same double (like Python's repr; "NaN" and
// "Infinity" are not produced: callers must check finiteness first).
std::string format_double(double value);
// printf-style formatting into a std::string.
std::string strprintf(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// "1.5 MB" style sizes (decimal units).
std::string human_bytes(double bytes);
// Glob-like match with '*' (any run) and '?' (one char), used by --checks patterns.
bool wildcard_match(std::string_view pattern, std::string_view text);

// `text` with bytes that are not valid UTF-8 written as \xNN, so a message quoting hostile
// input stays printable and converts to a Python str.
std::string printable_utf8(std::string_view text);
// printable_utf8 with control characters escaped too (C0 and DEL as \xNN, C1 as \u00NN;
// '\n' kept when `keep_newlines`): outside input echoed in a message can neither forge a
// log line (CR, LF), move the cursor or recolour the terminal (ESC, CSI) nor cut the
// message short (NUL).
std::string printable_text(std::string_view text, bool keep_newlines = false);

}  // namespace nsg
