#include "nsg/core/json.h"

#include <utility>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg {
namespace {

using json = nlohmann::json;

// Builds the document from nlohmann's SAX events, refusing a repeated key and a nesting
// deeper than allowed as they arrive. Every event costs O(log n) at most (a key is looked
// up in its own object's map), so parsing is linear in the text up to that log factor.
// (nlohmann's callback parser, used before, rescans the parent container at every
// object_end to erase discarded values: 300 000 empty objects in an array took 36 s.)
class StrictBuilder {
 public:
  explicit StrictBuilder(int max_depth) : max_depth_(max_depth) {}

  json take() { return std::move(root_); }
  const std::string& refused_record() const { return refused_record_; }
  const std::string& refused_expected() const { return refused_expected_; }
  bool refused() const { return !refused_expected_.empty(); }
  // The parser's own error (invalid JSON, a number beyond double), if any.
  const std::string& parse_message() const { return parse_message_; }
  bool parse_failed() const { return parse_failed_; }
  bool parse_error_has_byte() const { return parse_error_has_byte_; }
  size_t parse_error_byte() const { return parse_error_byte_; }

  bool null() { return put(json(nullptr)) != nullptr; }
  bool boolean(bool b) { return put(json(b)) != nullptr; }
  bool number_integer(json::number_integer_t x) { return put(json(x)) != nullptr; }
  bool number_unsigned(json::number_unsigned_t x) { return put(json(x)) != nullptr; }
  bool number_float(json::number_float_t x, const json::string_t&) { return put(json(x)) != nullptr; }
  bool string(json::string_t& s) { return put(json(std::move(s))) != nullptr; }
  bool binary(json::binary_t& b) { return put(json::binary(std::move(b))) != nullptr; }

  bool start_object(size_t) { return open(json::object()); }
  bool start_array(size_t) { return open(json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(json::string_t& k) {
    // Only called inside an object: the top of the stack is that object.
    if (open_.back()->contains(k)) return refuse("key \"" + printable_utf8(k) + "\"", "each key once in its object");
    key_ = std::move(k);
    return true;
  }

  bool parse_error(size_t byte, const std::string&, const nlohmann::detail::exception& e) {
    parse_failed_ = true;
    parse_error_has_byte_ = dynamic_cast<const json::parse_error*>(&e) != nullptr;
    parse_error_byte_ = byte;
    parse_message_ = printable_utf8(e.what());
    return false;
  }

 private:
  // Places `value` in the container being read (or as the root); its address, which stays
  // valid while it is the innermost open container (no sibling is added before it closes).
  json* put(json value) {
    if (open_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    json& parent = *open_.back();
    if (parent.is_array()) {
      parent.push_back(std::move(value));
      return &parent.back();
    }
    json& slot = parent[key_];
    slot = std::move(value);
    return &slot;
  }

  bool open(json container) {
    // open_.size() counts the containers around this one.
    const int depth = static_cast<int>(open_.size()) + 1;
    if (depth > max_depth_)
      return refuse("nesting depth " + std::to_string(depth),
                    "arrays and objects nested at most " + std::to_string(max_depth_) + " deep");
    open_.push_back(put(std::move(container)));
    return true;
  }

  bool close() {
    open_.pop_back();
    return true;
  }

  bool refuse(std::string record, std::string expected) {
    refused_record_ = std::move(record);
    refused_expected_ = std::move(expected);
    return false;
  }

  int max_depth_;
  json root_;
  std::vector<json*> open_;  // the containers being read, outermost first
  std::string key_;          // the key of the next value in the innermost object
  std::string refused_record_, refused_expected_;
  std::string parse_message_;
  bool parse_failed_ = false, parse_error_has_byte_ = false;
  size_t parse_error_byte_ = 0;
};

}  // namespace

nlohmann::json parse_json_strict(std::string_view text, const std::string& label, const std::string& what,
                                 int max_depth) {
  const std::string suffix = what.empty() ? "" : " (" + what + ")";
  StrictBuilder builder(max_depth);
  const bool ok = json::sax_parse(text.begin(), text.end(), &builder);
  if (builder.refused()) throw ParseError(label, builder.refused_record(), builder.refused_expected() + suffix);
  if (!ok || builder.parse_failed()) {
    const std::string record =
        builder.parse_error_has_byte() ? "byte " + std::to_string(builder.parse_error_byte()) : "";
    throw ParseError(label, record, "valid JSON" + suffix + ": " + builder.parse_message());
  }
  return builder.take();
}

}  // namespace nsg
