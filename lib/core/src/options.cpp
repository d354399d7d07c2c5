#include "nsg/core/options.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "nsg/core/files.h"
#include "nsg/core/strings.h"

namespace nsg::options {

namespace {

std::string number_text(double v) {
  if (v == std::floor(v) && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  return format_double(v);
}

// The value as written, shortened for a message.
std::string got(const Json& v) {
  std::string text = v.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return " (got " + text + ")";
}

}  // namespace

size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

bool Range::contains(double v) const {
  if (!only.empty()) return std::find(only.begin(), only.end(), v) != only.end();
  if (min && (min_open ? !(v > *min) : !(v >= *min))) return false;
  if (max && (max_open ? !(v < *max) : !(v <= *max))) return false;
  return true;
}

std::string Range::describe() const {
  if (!only.empty()) {
    std::string out;
    for (size_t i = 0; i < only.size(); ++i)
      out += (i == 0 ? "" : i + 1 == only.size() ? " or " : ", ") + number_text(only[i]);
    return out;
  }
  if (min && max)
    return "in " + std::string(min_open ? "(" : "[") + number_text(*min) + ", " + number_text(*max) +
           (max_open ? ")" : "]");
  if (min) return (min_open ? "> " : "≥ ") + number_text(*min);
  if (max) return (max_open ? "< " : "≤ ") + number_text(*max);
  return "";
}

Range at_least(double min) { return Range{min, std::nullopt, false, false, {}}; }
Range above(double min) { return Range{min, std::nullopt, true, false, {}}; }
Range between(double lo, double hi) { return Range{lo, hi, false, false, {}}; }
Range above_up_to(double lo, double hi) { return Range{lo, hi, true, false, {}}; }
Range one_of(std::vector<double> values) { return Range{std::nullopt, std::nullopt, false, false, std::move(values)}; }

std::string Spec::expected() const {
  const std::string range_text = range.describe();
  const std::string unit_text = unit.empty() ? "" : " (" + unit + ")";
  if (type == "number" || type == "integer") {
    if (!range.only.empty()) return range_text + unit_text;
    const std::string what = type == "number" ? "a number" : "an integer";
    return what + (range_text.empty() ? "" : " " + range_text) + unit_text;
  }
  if (type == "boolean") return "true or false";
  if (type == "string") return non_empty ? "a non-empty string" : "a string";
  if (type == "choice") {
    std::string out;
    for (size_t i = 0; i < choices.size(); ++i)
      out += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + ("\"" + choices[i] + "\"");
    return out;
  }
  return shape_expected;
}

OrderedJson Spec::schema() const {
  OrderedJson s = OrderedJson::object();
  s["description"] = description + (unit.empty() ? "" : " (" + unit + ")");
  if (type == "number" || type == "integer") {
    if (!range.only.empty()) {
      OrderedJson values = OrderedJson::array();
      for (double v : range.only) {
        if (type == "integer") values.push_back(static_cast<int64_t>(v));
        else values.push_back(v);
      }
      s["enum"] = values;
      return s;
    }
    s["type"] = type;
    const auto bound = [&](double v) {
      return type == "integer" ? OrderedJson(static_cast<int64_t>(v)) : OrderedJson(v);
    };
    if (range.min) s[range.min_open ? "exclusiveMinimum" : "minimum"] = bound(*range.min);
    if (range.max) s[range.max_open ? "exclusiveMaximum" : "maximum"] = bound(*range.max);
  } else if (type == "boolean" || type == "string") {
    s["type"] = type;
    if (non_empty) s["minLength"] = 1;
  } else if (type == "choice") {
    s["enum"] = choices;
  } else {
    for (const auto& [k, v] : shape_schema.items()) s[k] = v;
  }
  return s;
}

[[noreturn]] void reject(const Json& v, const Spec& spec) { throw ConfigError("", spec.key, spec.expected() + got(v)); }

double read_number(const Json& v, const Spec& spec) {
  if (!v.is_number()) reject(v, spec);
  const double d = v.get<double>();
  if (!std::isfinite(d) || !spec.range.contains(d)) reject(v, spec);
  return d;
}

int64_t read_integer(const Json& v, const Spec& spec) {
  const bool integral =
      v.is_number_integer() || (v.is_number_float() && std::isfinite(v.get<double>()) &&
                                std::floor(v.get<double>()) == v.get<double>() && std::abs(v.get<double>()) < 9e18);
  if (!integral || (v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(std::numeric_limits<int64_t>::max())))
    reject(v, spec);
  const int64_t x = v.get<int64_t>();
  if (!spec.range.contains(static_cast<double>(x))) reject(v, spec);
  return x;
}

uint64_t read_unsigned(const Json& v, const Spec& spec) {
  if (v.is_number_unsigned()) return v.get<uint64_t>();
  if (v.is_number_integer() && v.get<int64_t>() >= 0) return static_cast<uint64_t>(v.get<int64_t>());
  reject(v, spec);
}

bool read_boolean(const Json& v, const Spec& spec) {
  if (!v.is_boolean()) reject(v, spec);
  return v.get<bool>();
}

std::string read_string(const Json& v, const Spec& spec) {
  if (!v.is_string() || (spec.non_empty && v.get_ref<const std::string&>().empty())) reject(v, spec);
  return v.get<std::string>();
}

std::vector<std::string> keys_of(const std::vector<Spec>& specs) {
  std::vector<std::string> keys;
  for (const Spec& s : specs) keys.push_back(s.key);
  return keys;
}

bool is_section(const std::vector<std::string>& keys, const std::string& path) {
  return std::any_of(keys.begin(), keys.end(), [&](const std::string& k) {
    return k.size() > path.size() && k.compare(0, path.size(), path) == 0 && k[path.size()] == '.';
  });
}

std::string did_you_mean(const std::string& key, const std::vector<std::string>& keys) {
  // The closest key by edit distance, or by last part alone ("min_coverage" for
  // "crops.min_lidar_coverage" is too far; "crops.min_lidar_coverge" is close).
  std::string best;
  size_t best_distance = std::max<size_t>(3, key.size() / 4) + 1;
  const std::string leaf = key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1);
  for (const std::string& k : keys) {
    const std::string k_leaf = k.substr(k.rfind('.') == std::string::npos ? 0 : k.rfind('.') + 1);
    const size_t d = std::min(edit_distance(key, k), edit_distance(leaf, k_leaf) + 1);
    if (d < best_distance) {
      best_distance = d;
      best = k;
    }
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

void insert_at(OrderedJson& doc, const std::string& dotted_key, OrderedJson value) {
  OrderedJson* node = &doc;
  const std::vector<std::string> parts = split(dotted_key, '.');
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    OrderedJson& next = (*node)[parts[i]];
    if (!next.is_object()) next = OrderedJson::object();
    node = &next;
  }
  (*node)[parts.back()] = std::move(value);
}

OrderedJson value_at(const OrderedJson& doc, const std::string& dotted_key) {
  const OrderedJson* node = &doc;
  for (const std::string& part : split(dotted_key, '.')) {
    if (!node->is_object() || !node->contains(part)) return OrderedJson();
    node = &(*node)[part];
  }
  return *node;
}

[[noreturn]] void unknown_key(const std::string& source, const std::string& key, const std::vector<std::string>& keys) {
  throw ConfigError(source, key, "a known config key" + did_you_mean(key, keys) + "; `--list-options` lists them");
}

[[noreturn]] void not_a_section(const std::string& source, const std::string& path) {
  throw ConfigError(source, path, path.empty() ? "a JSON object (the config)" : "an object (the section's keys)");
}

[[noreturn]] void rethrow_with_source(const ConfigError& e, const std::string& source, const std::string& key) {
  throw ConfigError(source, e.record().empty() ? key : e.record(), e.expected());
}

OrderedJson config_schema(const std::vector<Spec>& specs, const std::string& id, const std::string& title,
                          const std::string& description) {
  const auto object = [] {
    return OrderedJson{{"type", "object"}, {"additionalProperties", false}, {"properties", OrderedJson::object()}};
  };
  OrderedJson root{{"$schema", "http://json-schema.org/draft-07/schema#"},
                   {"$id", id},
                   {"title", title},
                   {"description", description}};
  const OrderedJson empty_object = object();
  for (const auto& [k, v] : empty_object.items()) root[k] = v;
  for (const Spec& s : specs) {
    OrderedJson* node = &root;
    const std::vector<std::string> parts = split(s.key, '.');
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
      OrderedJson& props = (*node)["properties"];
      if (!props.contains(parts[i])) props[parts[i]] = object();
      node = &props[parts[i]];
    }
    (*node)["properties"][parts.back()] = s.schema();
  }
  return root;
}

std::string list_options(const std::vector<Spec>& specs, const OrderedJson& defaults, const std::string& format) {
  const auto type_of = [](const Spec& s) {
    if (s.type == "choice" || (!s.range.only.empty())) return s.expected();
    if (s.type == "shape") return s.shape_expected;
    const std::string r = s.range.describe();
    return s.type + (r.empty() ? "" : " " + r);
  };
  if (format == "json") {
    OrderedJson out = OrderedJson::array();
    for (const Spec& s : specs)
      out.push_back({{"key", s.key},
                     {"type", type_of(s)},
                     {"default", value_at(defaults, s.key)},
                     {"unit", s.unit},
                     {"description", s.description}});
    return out.dump(2) + "\n";
  }
  std::ostringstream os;
  if (format == "md") {
    os << "| key | type | default | unit | description |\n| --- | --- | --- | --- | --- |\n";
    const auto cell = [](std::string text) {
      std::string out;
      for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
      return out;
    };
    for (const Spec& s : specs)
      os << "| `" << s.key << "` | " << cell(type_of(s)) << " | `" << cell(value_at(defaults, s.key).dump()) << "` | "
         << s.unit << " | " << cell(s.description) << " |\n";
    return os.str();
  }
  if (format != "text") throw ConfigError("", "--format", "text, md or json (got '" + format + "')");
  for (const Spec& s : specs) {
    std::string value = value_at(defaults, s.key).dump();
    if (value.size() > 40) value = value.substr(0, 37) + "...";
    os << s.key << "  " << type_of(s) << (s.unit.empty() ? "" : ", " + s.unit) << "  default " << value << "\n    "
       << s.description << "\n";
  }
  return os.str();
}

Json parse_config_text(const std::string& text, const std::string& source) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw ParseError(source, "byte " + std::to_string(e.byte), "valid JSON (" + std::string(e.what()) + ")");
  }
}

Json read_config_file(const std::filesystem::path& file) { return parse_config_text(read_file(file), file.string()); }

std::pair<std::string, Json> parse_assignment(const std::string& assignment, const std::string& example) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("--set", assignment, "key=value (e.g. " + example + "; --list-options lists the keys)");
  const std::string text = assignment.substr(eq + 1);
  Json value;
  try {
    value = Json::parse(text);
  } catch (const Json::parse_error&) {
    value = text;  // anything else is a string
  }
  return {assignment.substr(0, eq), value};
}

Json flag_text_value(const Spec& spec, const std::string& text) {
  if (spec.type == "string") return text;
  try {
    return Json::parse(text);  // numbers, booleans, arrays, objects
  } catch (const Json::parse_error&) {
    return text;  // anything else is a string (the setter names the key when it is wrong)
  }
}

void rethrow_from_origin(const ConfigError& e, const Origins& origins) {
  std::string source = "defaults";
  for (const auto& [key, from] : origins)
    if (key == e.record() || starts_with(key, e.record() + ".") || starts_with(e.record(), key + ".")) source = from;
  throw ConfigError(source, e.record(), e.expected());
}

}  // namespace nsg::options
