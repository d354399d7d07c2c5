#pragma once
// Declared options (PDAL's discipline): an options struct lists each of its config keys
// once — the key as written in the config file, its type, unit, allowed range or choices
// and a one-line description; the default is the struct's own member initializer. Every
// use comes from that list: reading a config document (unknown keys are errors with a
// "did you mean"), --set, range errors naming the key and the file or flag the value came
// from, the resolved config as JSON, --list-options and the JSON Schema. A value is
// range-checked once, when it is set; validate() of a struct built in code runs the same
// setters over its values.
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"

namespace nsg::options {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

// Where each key's value came from (a config file's path, "--set", a flag): key → source.
using Origins = std::map<std::string, std::string>;

// Allowed numbers: [min, max] with open ends where marked; `only` lists the allowed values.
struct Range {
  std::optional<double> min, max;
  bool min_open = false, max_open = false;
  std::vector<double> only;
  bool contains(double v) const;
  std::string describe() const;  // "in (0, 10]", "≥ 0", "1, 2 or 4"; "" when unbounded
};
Range at_least(double min);               // [min, ∞)
Range above(double min);                  // (min, ∞)
Range between(double lo, double hi);      // [lo, hi]
Range above_up_to(double lo, double hi);  // (lo, hi]
Range one_of(std::vector<double> values);

// What listings, schemas and messages read of a declaration.
struct Spec {
  std::string key;          // dotted path as written in the config file
  std::string type;         // number, integer, boolean, string, choice, or a shape's name
  std::string unit;         // m, px, MB, ... ("" = none)
  std::string description;  // one line
  Range range;
  std::vector<std::string> choices;  // type "choice"
  bool non_empty = false;            // strings
  OrderedJson shape_schema;          // a shape's JSON Schema (type is then its phrase)
  std::string shape_expected;        // a shape's "expected" phrase

  std::string expected() const;  // "a number in [0, 1]", "\"tar\" or \"folder\"", ...
  OrderedJson schema() const;    // the value's JSON Schema, with the description
};

// Typed reads of one value under `spec`; ConfigError("", spec.key, expected (got …)).
double read_number(const Json& v, const Spec& spec);
int64_t read_integer(const Json& v, const Spec& spec);
uint64_t read_unsigned(const Json& v, const Spec& spec);
bool read_boolean(const Json& v, const Spec& spec);
std::string read_string(const Json& v, const Spec& spec);
[[noreturn]] void reject(const Json& v, const Spec& spec);

template <typename Owner>
struct Option {
  Spec spec;
  std::function<OrderedJson(const Owner&)> get;
  // Checks `value` against the spec and stores it; ConfigError("", key or a path below it, …).
  std::function<void(Owner&, const Json&, const Spec&)> set;

  Option& unit(std::string u) {
    spec.unit = std::move(u);
    return *this;
  }
  Option& range(Range r) {
    spec.range = std::move(r);
    return *this;
  }
  Option& help(std::string d) {
    spec.description = std::move(d);
    return *this;
  }
  Option& non_empty() {
    spec.non_empty = true;
    return *this;
  }
  // Runs `f` after every set: a value that also sets a derived field.
  Option& then(std::function<void(Owner&)> f) {
    set = [s = set, f = std::move(f)](Owner& o, const Json& v, const Spec& sp) {
      s(o, v, sp);
      f(o);
    };
    return *this;
  }
};

// The declarations of one options struct (or of a config made of several).
template <typename Owner>
class Table {
 public:
  Option<Owner>& number(std::string key, double Owner::*field) {
    return add(
        std::move(key), "number", [field](const Owner& o) { return OrderedJson(o.*field); },
        [field](Owner& o, const Json& v, const Spec& s) { o.*field = read_number(v, s); });
  }
  template <typename Int>
  Option<Owner>& integer(std::string key, Int Owner::*field) {
    static_assert(std::is_integral_v<Int>);
    return add(
        std::move(key), "integer", [field](const Owner& o) { return OrderedJson(o.*field); },
        [field](Owner& o, const Json& v, const Spec& s) {
          if constexpr (std::is_unsigned_v<Int>) {
            o.*field = static_cast<Int>(read_unsigned(v, s));
          } else {
            const int64_t x = read_integer(v, s);
            if (x < std::numeric_limits<Int>::min() || x > std::numeric_limits<Int>::max()) reject(v, s);
            o.*field = static_cast<Int>(x);
          }
        });
  }
  Option<Owner>& boolean(std::string key, bool Owner::*field) {
    return add(
        std::move(key), "boolean", [field](const Owner& o) { return OrderedJson(o.*field); },
        [field](Owner& o, const Json& v, const Spec& s) { o.*field = read_boolean(v, s); });
  }
  Option<Owner>& text(std::string key, std::string Owner::*field) {
    return add(
        std::move(key), "string", [field](const Owner& o) { return OrderedJson(o.*field); },
        [field](Owner& o, const Json& v, const Spec& s) { o.*field = read_string(v, s); });
  }
  Option<Owner>& path(std::string key, std::filesystem::path Owner::*field) {
    return add(
        std::move(key), "string", [field](const Owner& o) { return OrderedJson((o.*field).string()); },
        [field](Owner& o, const Json& v, const Spec& s) { o.*field = read_string(v, s); });
  }
  // An enum written as one of `names`.
  template <typename E>
  Option<Owner>& choice(std::string key, E Owner::*field, std::vector<std::pair<std::string, E>> names) {
    Option<Owner>& opt = add(
        std::move(key), "choice",
        [field, names](const Owner& o) {
          for (const auto& [name, e] : names)
            if (e == o.*field) return OrderedJson(name);
          return OrderedJson();
        },
        [field, names](Owner& o, const Json& v, const Spec& s) {
          if (v.is_string())
            for (const auto& [name, e] : names)
              if (name == v.get_ref<const std::string&>()) {
                o.*field = e;
                return;
              }
          reject(v, s);
        });
    for (const auto& [name, e] : names) opt.spec.choices.push_back(name);
    return opt;
  }
  // A value of its own shape (a list of records, a value that sets two fields): the
  // setter checks it (read_* and reject name the key) and `schema` describes it.
  Option<Owner>& shape(std::string key, std::string expected, OrderedJson schema,
                       std::function<OrderedJson(const Owner&)> get,
                       std::function<void(Owner&, const Json&, const Spec&)> set) {
    Option<Owner>& opt = add(std::move(key), "shape", std::move(get), std::move(set));
    opt.spec.shape_expected = std::move(expected);
    opt.spec.shape_schema = std::move(schema);
    return opt;
  }
  // Every declaration of `sub`, reached through `member` (keys unchanged).
  template <typename Sub>
  void include(Sub Owner::*member, const Table<Sub>& sub) {
    for (const Option<Sub>& s : sub.options()) {
      Option<Owner> o;
      o.spec = s.spec;
      o.get = [member, g = s.get](const Owner& owner) { return g(owner.*member); };
      o.set = [member, f = s.set](Owner& owner, const Json& v, const Spec& spec) { f(owner.*member, v, spec); };
      options_.push_back(std::move(o));
    }
  }

  const std::deque<Option<Owner>>& options() const { return options_; }
  std::vector<Spec> specs() const {
    std::vector<Spec> out;
    for (const Option<Owner>& o : options_) out.push_back(o.spec);
    return out;
  }
  const Option<Owner>* find(const std::string& key) const {
    for (const Option<Owner>& o : options_)
      if (o.spec.key == key) return &o;
    return nullptr;
  }

  // The values as nested JSON in declaration order (the resolved config).
  OrderedJson to_json(const Owner& owner) const;
  // Sets every key of the (nested) document; `source` names the file or flag in errors.
  void apply(Owner& owner, const Json& doc, const std::string& source, Origins* origins = nullptr) const {
    apply_object(owner, doc, source, "", origins);
  }
  // Sets one key ("crops.min_lidar_coverage") or a key below a shape ("splits.regions.x").
  void set(Owner& owner, const std::string& key, const Json& value, const std::string& source,
           Origins* origins = nullptr) const;
  // Runs every declared value of `owner` through its setter: the range checks of a struct
  // built in code. ConfigError naming the key.
  void check(const Owner& owner) const {
    Owner scratch = owner;
    for (const Option<Owner>& o : options_) o.set(scratch, Json::parse(o.get(owner).dump()), o.spec);
  }

 private:
  Option<Owner>& add(std::string key, const char* type, std::function<OrderedJson(const Owner&)> get,
                     std::function<void(Owner&, const Json&, const Spec&)> set) {
    Option<Owner>& o = options_.emplace_back();
    o.spec.key = std::move(key);
    o.spec.type = type;
    o.get = std::move(get);
    o.set = std::move(set);
    return o;
  }
  void apply_object(Owner& owner, const Json& doc, const std::string& source, const std::string& path,
                    Origins* origins) const;
  void set_checked(Owner& owner, const Option<Owner>& o, const Json& value, const std::string& source,
                   Origins* origins) const;
  std::deque<Option<Owner>> options_;
};

// Non-template parts shared by every table.
size_t edit_distance(std::string_view a, std::string_view b);  // Levenshtein, for "did you mean"
std::vector<std::string> keys_of(const std::vector<Spec>& specs);
bool is_section(const std::vector<std::string>& keys, const std::string& path);
// " (did you mean 'crops.min_lidar_coverage'?)" for a close key, else "".
std::string did_you_mean(const std::string& key, const std::vector<std::string>& keys);
void insert_at(OrderedJson& doc, const std::string& dotted_key, OrderedJson value);
// The unknown-key and not-an-object errors of apply.
[[noreturn]] void unknown_key(const std::string& source, const std::string& key, const std::vector<std::string>& keys);
[[noreturn]] void not_a_section(const std::string& source, const std::string& path);
// ConfigError from a setter, re-thrown naming the source (and the key when it named none).
[[noreturn]] void rethrow_with_source(const ConfigError& e, const std::string& source, const std::string& key);

// A config document: JSON text parsed (ParseError naming `source` and the byte), or a
// file read and parsed (IoError / ParseError naming the file).
Json parse_config_text(const std::string& text, const std::string& source);
Json read_config_file(const std::filesystem::path& file);
// "key=value" as --set takes it: the key and the value parsed as JSON (numbers, booleans,
// arrays, objects, "quoted text"), else the text itself as a string. ConfigError naming
// --set and `example` ("crops.min_lidar_coverage=0.4") without an '='.
std::pair<std::string, Json> parse_assignment(const std::string& assignment, const std::string& example);
// A value a command-line flag gives a config key (`--seed 7` for "seed"); `flag` names
// the source in errors.
struct FlagValue {
  std::string flag;
  std::string key;
  Json value;
};
// A flag's text as the value of a key declared `spec`: a string key takes the text as
// written (`--version 1.0` is "1.0"), any other key parses it as JSON first, like --set.
Json flag_text_value(const Spec& spec, const std::string& text);

// The one precedence of every command with a config (generate, synth, train, frames;
// docs/options.md): the defaults, then the file ("" = none), then each --set "key=value"
// in the order given, then the flags that stand for keys — a dedicated flag is the most
// specific thing a user typed. `example` is --set's example in errors. The checks across
// keys are the caller's (they name the source a key came from through `origins`).
template <typename Owner>
Owner resolve_config(const Table<Owner>& table, const std::filesystem::path& file,
                     const std::vector<std::string>& settings, const std::vector<FlagValue>& flags,
                     const std::string& example, Origins& origins, Owner config = Owner{}) {
  if (!file.empty()) table.apply(config, read_config_file(file), file.string(), &origins);
  for (const std::string& s : settings) {
    const auto [key, value] = parse_assignment(s, example);
    table.set(config, key, value, "--set", &origins);
  }
  for (const FlagValue& f : flags) table.set(config, f.key, f.value, f.flag, &origins);
  return config;
}

// A check across keys (ConfigError naming one key) re-thrown naming the source that set
// that key, or a key above or below it, last ("defaults" when none did).
[[noreturn]] void rethrow_from_origin(const ConfigError& e, const Origins& origins);

// The JSON Schema (draft-07) of a config made of `specs`: nested objects, no other keys.
OrderedJson config_schema(const std::vector<Spec>& specs, const std::string& id, const std::string& title,
                          const std::string& description);
// --list-options: key, type, default, unit, description. format: "text", "md" or "json".
std::string list_options(const std::vector<Spec>& specs, const OrderedJson& defaults, const std::string& format);
// The value at a dotted key of a nested document (null when absent).
OrderedJson value_at(const OrderedJson& doc, const std::string& dotted_key);

// "schema_version": the format's version "1" (optional in a file; any other value is refused).
template <typename Owner>
Option<Owner>& schema_version_option(Table<Owner>& t) {
  return t
      .shape(
          "schema_version", "\"1\"", {{"const", "1"}}, [](const Owner&) { return OrderedJson("1"); },
          [](Owner&, const Json& v, const Spec& s) {
            if (v != "1") reject(v, s);
          })
      .help("Version of this format");
}

template <typename Owner>
OrderedJson Table<Owner>::to_json(const Owner& owner) const {
  OrderedJson doc = OrderedJson::object();
  for (const Option<Owner>& o : options_) insert_at(doc, o.spec.key, o.get(owner));
  return doc;
}

template <typename Owner>
void Table<Owner>::set_checked(Owner& owner, const Option<Owner>& o, const Json& value, const std::string& source,
                               Origins* origins) const {
  try {
    o.set(owner, value, o.spec);
  } catch (const ConfigError& e) {
    rethrow_with_source(e, source, o.spec.key);
  }
  if (origins) (*origins)[o.spec.key] = source;
}

template <typename Owner>
void Table<Owner>::apply_object(Owner& owner, const Json& doc, const std::string& source, const std::string& path,
                                Origins* origins) const {
  if (!doc.is_object()) not_a_section(source, path);
  const std::vector<std::string> keys = keys_of(specs());
  for (const auto& [name, value] : doc.items()) {
    const std::string key = path.empty() ? name : path + "." + name;
    if (const Option<Owner>* o = find(key)) {
      set_checked(owner, *o, value, source, origins);
    } else if (is_section(keys, key)) {
      apply_object(owner, value, source, key, origins);
    } else {
      unknown_key(source, key, keys);
    }
  }
}

template <typename Owner>
void Table<Owner>::set(Owner& owner, const std::string& key, const Json& value, const std::string& source,
                       Origins* origins) const {
  if (const Option<Owner>* o = find(key)) return set_checked(owner, *o, value, source, origins);
  // "splits.regions.boston-seaport": a key below a shape patches the shape's value; a
  // section ("crops") takes an object of its keys.
  for (const Option<Owner>& o : options_) {
    const std::string& k = o.spec.key;
    if (key.size() > k.size() && key.compare(0, k.size(), k) == 0 && key[k.size()] == '.') {
      OrderedJson whole = o.get(owner);
      insert_at(whole, key.substr(k.size() + 1), OrderedJson::parse(value.dump()));
      return set_checked(owner, o, Json::parse(whole.dump()), source, origins);
    }
  }
  Json doc = value;
  const std::vector<std::string> keys = keys_of(specs());
  if (!is_section(keys, key)) unknown_key(source, key, keys);
  apply_object(owner, doc, source, key, origins);
}

}  // namespace nsg::options
