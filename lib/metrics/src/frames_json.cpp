// The strict simdjson DOM parse of frame documents.
#include "frames_json.h"

#include <algorithm>
#include <string_view>
#include <vector>

#include "nsg/validate/submission.h"

namespace nsg::metrics::detail {
namespace {

// Walks the document once: values counted, objects' keys checked for repeats. `path` holds
// the reference tokens down to the value (for the pointer of a problem).
class StrictWalk {
 public:
  StrictWalk(const std::string& label, int64_t max_values, Issues& issues)
      : label_(label), max_values_(max_values), issues_(issues) {}

  bool walk(simdjson::dom::element e) {
    if (++values_ > max_values_) {
      issues_.error("submission.size", label_ + ":",
                    "expected at most " + std::to_string(max_values_) + " JSON values (numbers, strings, arrays, …)");
      return false;
    }
    simdjson::dom::object obj;
    simdjson::dom::array arr;
    if (e.get_object().get(obj) == simdjson::SUCCESS) {
      std::vector<std::string_view> keys;
      for (const auto field : obj) {
        keys.push_back(field.key);
        path_.push_back({field.key, 0});
        if (!walk(field.value)) return false;
        path_.pop_back();
      }
      std::sort(keys.begin(), keys.end());
      const auto twice = std::adjacent_find(keys.begin(), keys.end());
      if (twice != keys.end()) {
        issues_.error("submission.json",
                      label_ + ":" + pointer() + "/" + validate::json_pointer_token(std::string(*twice)),
                      "expected each key once in an object (JSON leaves a repeated key's meaning open)");
        return false;
      }
    } else if (e.get_array().get(arr) == simdjson::SUCCESS) {
      size_t i = 0;
      for (const auto item : arr) {
        path_.push_back({{}, i++});
        if (!walk(item)) return false;
        path_.pop_back();
      }
    }
    return true;
  }

 private:
  std::string pointer() const {
    std::string out;
    for (const Step& t : path_) {
      out += '/';
      out += t.key.data() != nullptr ? validate::json_pointer_token(std::string(t.key)) : std::to_string(t.index);
    }
    return out;
  }

  const std::string& label_;
  int64_t max_values_;
  Issues& issues_;
  int64_t values_ = 0;
  struct Step {
    std::string_view key;  // an object member (data() set), else an array index
    size_t index;
  };
  std::vector<Step> path_;  // views into the parsed document, which outlives the walk
};

}  // namespace

bool parse_strict(simdjson::dom::parser& parser, const simdjson::padded_string& text, const std::string& label,
                  int max_depth, int64_t max_values, simdjson::dom::element& doc, Issues& issues) {
  // The parser's own depth limit (one level for the document itself); its buffers are kept
  // when they are large enough (a split's records reuse one parser).
  const size_t capacity = std::max<size_t>(text.size(), 64), depth = static_cast<size_t>(max_depth) + 1;
  if ((parser.capacity() < capacity || parser.max_depth() != depth) &&
      parser.allocate(capacity, depth) != simdjson::SUCCESS) {
    issues.error("submission.size", label + ":", "expected a file the parser can allocate for");
    return false;
  }
  const simdjson::error_code ec = parser.parse(text).get(doc);
  if (ec == simdjson::DEPTH_ERROR) {
    issues.error("submission.size", label + ":", "expected nesting at most " + std::to_string(max_depth) + " deep");
    return false;
  }
  if (ec != simdjson::SUCCESS) {
    issues.error("submission.json", label + ":",
                 std::string("expected JSON (NaN and Infinity are not JSON): ") + simdjson::error_message(ec));
    return false;
  }
  return StrictWalk(label, max_values, issues).walk(doc);
}

std::optional<double> number(simdjson::dom::element e) {
  double v = 0.0;
  if (e.get_double().get(v) == simdjson::SUCCESS) return v;
  int64_t i = 0;
  if (e.get_int64().get(i) == simdjson::SUCCESS) return static_cast<double>(i);
  uint64_t u = 0;
  if (e.get_uint64().get(u) == simdjson::SUCCESS) return static_cast<double>(u);
  return std::nullopt;
}

}  // namespace nsg::metrics::detail
