#include "nsg/core/json.h"

#include <unordered_set>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg {
namespace {

// Thrown out of the parser callback; turned into a ParseError with the label.
struct Refused {
  std::string record, expected;
};

}  // namespace

nlohmann::json parse_json_strict(std::string_view text, const std::string& label, const std::string& what,
                                 int max_depth) {
  using Event = nlohmann::json::parse_event_t;
  std::vector<std::unordered_set<std::string>> keys;  // of the objects being read
  const auto check = [&](int depth, Event event, nlohmann::json& parsed) {
    // `depth` counts the containers around this one.
    if ((event == Event::object_start || event == Event::array_start) && depth + 1 > max_depth)
      throw Refused{"nesting depth " + std::to_string(depth + 1),
                    "arrays and objects nested at most " + std::to_string(max_depth) + " deep"};
    if (event == Event::object_start) keys.emplace_back();
    if (event == Event::object_end && !keys.empty()) keys.pop_back();
    if (event == Event::key && !keys.empty() && !keys.back().insert(parsed.get<std::string>()).second)
      throw Refused{"key \"" + printable_utf8(parsed.get<std::string>()) + "\"", "each key once in its object"};
    return true;
  };
  const std::string suffix = what.empty() ? "" : " (" + what + ")";
  try {
    return nlohmann::json::parse(text.begin(), text.end(), check);
  } catch (const Refused& r) {
    throw ParseError(label, r.record, r.expected + suffix);
  } catch (const nlohmann::json::parse_error& e) {
    throw ParseError(label, "byte " + std::to_string(e.byte), "valid JSON" + suffix + ": " + printable_utf8(e.what()));
  } catch (const nlohmann::json::exception& e) {  // e.g. a number beyond double (1e777): out_of_range
    throw ParseError(label, "", "valid JSON" + suffix + ": " + printable_utf8(e.what()));
  }
}

std::string printable_utf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  const auto* u = reinterpret_cast<const unsigned char*>(text.data());
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    const unsigned char c = u[i];
    // Length of a well-formed sequence starting here (RFC 3629), 0 if ill-formed.
    size_t len = 0;
    if (c < 0x80) len = 1;
    else if (c >= 0xC2 && c <= 0xDF) len = 2;
    else if (c >= 0xE0 && c <= 0xEF) len = 3;
    else if (c >= 0xF0 && c <= 0xF4) len = 4;
    if (len > 1) {
      if (i + len > n) len = 0;
      for (size_t k = 1; k < len; ++k)
        if ((u[i + k] & 0xC0) != 0x80) len = 0;
      if (len == 3 && ((c == 0xE0 && u[i + 1] < 0xA0) || (c == 0xED && u[i + 1] >= 0xA0))) len = 0;
      if (len == 4 && ((c == 0xF0 && u[i + 1] < 0x90) || (c == 0xF4 && u[i + 1] >= 0x90))) len = 0;
    }
    if (len == 0) {
      out += strprintf("\\x%02X", c);
      ++i;
    } else {
      out.append(text.substr(i, len));
      i += len;
    }
  }
  return out;
}

}  // namespace nsg
