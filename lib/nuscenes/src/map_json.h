#pragma once
// The JSON layer of the map expansion reader (simdjson on-demand), shared by map_parse.cpp:
// where the reader is (Ctx, for error messages), scalar and list readers, and declarative
// record layouts (Field lists read in any key order). Internal to lib/nuscenes.
#include <simdjson.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "map_defects.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg::nuscenes::map_detail {

namespace od = simdjson::ondemand;

// Where the reader is; used to build error messages and to name records in defects.
struct Ctx {
  std::string file;
  std::string_view layer;           // "lane", "arcline_path_3", … ("" at the top level)
  size_t index = 0;                 // record position in its array
  std::string token;                // record token once known (arcline/connectivity: the map key)
  std::string_view key;             // field being read
  bool in_list = false;             // arcline paths: index is the path number within the token's list
  MapDefectLog* defects = nullptr;  // where null tokens and "" links are reported

  std::string record() const {
    if (layer.empty()) return {};
    std::string out(layer);
    if (!token.empty()) out += " '" + token + "'";
    if (token.empty() || in_list) out += strprintf(" %s#%zu", in_list ? "path " : "", index);
    return out;
  }
  std::string field_prefix() const { return key.empty() ? std::string() : "key \"" + std::string(key) + "\": "; }
  [[noreturn]] void parse_fail(const std::string& expected, simdjson::error_code ec = simdjson::SUCCESS) const {
    std::string what = field_prefix() + "expected " + expected;
    if (ec != simdjson::SUCCESS) what += std::string(" (JSON: ") + simdjson::error_message(ec) + ")";
    throw ParseError(file, record(), what);
  }
  [[noreturn]] void data_fail(const std::string& expected) const {
    throw DataError(file, record(), field_prefix() + "expected " + expected);
  }
};

// ---- scalar and list readers ---------------------------------------------------------

inline std::string_view get_string(od::value& v, const Ctx& c) {
  std::string_view s;
  if (auto ec = v.get_string().get(s)) c.parse_fail("a string", ec);
  return s;
}

inline double get_number(od::value& v, const Ctx& c) {
  double d;
  if (auto ec = v.get_double().get(d)) c.parse_fail("a finite number", ec);
  if (!std::isfinite(d)) c.parse_fail("a finite number");
  return d;
}

inline bool get_bool(od::value& v, const Ctx& c) {
  bool b;
  if (auto ec = v.get_bool().get(b)) c.parse_fail("true or false", ec);
  return b;
}

inline od::array get_array(od::value& v, const Ctx& c, const char* what) {
  od::array a;
  if (auto ec = v.get_array().get(a)) c.parse_fail(what, ec);
  return a;
}

// Calls f(element_value, position) for each element of a JSON array.
template <class F>
void for_each_element(od::value& v, const Ctx& c, const char* what, F&& f) {
  od::array array = get_array(v, c, what);
  size_t i = 0;
  for (auto element : array) {
    od::value ev;
    if (auto ec = std::move(element).get(ev)) c.parse_fail(what, ec);
    f(ev, i++);
  }
}

inline std::vector<std::string> get_string_list(od::value& v, const Ctx& c) {
  std::vector<std::string> out;
  for_each_element(v, c, "an array of strings", [&](od::value& ev, size_t) { out.emplace_back(get_string(ev, c)); });
  return out;
}

template <size_t N>
std::array<double, N> get_numbers(od::value& v, const Ctx& c) {
  std::array<double, N> out{};
  const std::string what = strprintf("an array of %zu finite numbers", N);
  size_t count = 0;
  for_each_element(v, c, what.c_str(), [&](od::value& ev, size_t i) {
    if (i >= N) c.parse_fail(what);
    out[i] = get_number(ev, c);
    count = i + 1;
  });
  if (count != N) c.parse_fail(what);
  return out;
}

// A token or a link to one. Real maps hold JSON null where a token is expected (#810,
// #862, #1183) and the devkit indexes and looks those up as None; null reads as "" (so a
// null link finds the record whose own token is null) and is reported, as is a "" link.
inline std::string_view get_token(od::value& v, const Ctx& c) {
  std::string_view s;
  const auto ec = v.get_string().get(s);
  if (ec == simdjson::SUCCESS) {
    if (s.empty() && c.defects != nullptr) {
      const bool own = c.key == "token";
      c.defects->add(Severity::kInfo, own ? "map.empty_token" : "map.empty_link", c.layer, c.key,
                     record_label(c.token, c.index),
                     own ? "is \"\"; kept, like the devkit" : "is \"\" (links to nothing); kept, like the devkit");
    }
    return s;
  }
  bool is_null = false;
  if (v.is_null().get(is_null) != simdjson::SUCCESS || !is_null) c.parse_fail("a string (or null)", ec);
  if (c.defects != nullptr) {
    c.defects->add(Severity::kInfo, "map.null_token", c.layer, c.key, record_label(c.token, c.index),
                   "is null; read as \"\", which finds the record whose own token is null (the devkit's "
                   "lookup of None)");
  }
  return {};
}

inline std::vector<std::string> get_token_list(od::value& v, const Ctx& c) {
  std::vector<std::string> out;
  for_each_element(v, c, "an array of strings", [&](od::value& ev, size_t) { out.emplace_back(get_token(ev, c)); });
  return out;
}

// ---- declarative record layouts -------------------------------------------------------

template <class R>
struct Field {
  std::string_view key;
  void (*read)(od::value& v, Ctx& c, R& r);
  bool required = true;
};

template <class R, std::string R::*M>
void string_field(od::value& v, Ctx& c, R& r) {
  r.*M = std::string(get_string(v, c));
}
template <class R, std::vector<std::string> R::*M>
void string_list_field(od::value& v, Ctx& c, R& r) {
  r.*M = get_string_list(v, c);
}
template <class R, double R::*M>
void number_field(od::value& v, Ctx& c, R& r) {
  r.*M = get_number(v, c);
}
template <class R, bool R::*M>
void bool_field(od::value& v, Ctx& c, R& r) {
  r.*M = get_bool(v, c);
}

// Reads the fields of one JSON object into `r`: keys in any order, unknown keys skipped
// (forward compatible; also "token", read before by read_record), each known key at most
// once, required keys present.
template <class R, size_t N>
void read_fields(od::object& object, Ctx& c, const std::array<Field<R>, N>& spec, R& r) {
  static_assert(N < 64);
  std::uint64_t seen = 0;
  for (auto field_result : object) {
    od::field field;
    c.key = {};
    if (auto ec = std::move(field_result).get(field)) c.parse_fail("a key/value pair", ec);
    std::string_view key;
    if (auto ec = field.unescaped_key().get(key)) c.parse_fail("a string key", ec);
    size_t k = 0;
    while (k < N && spec[k].key != key) ++k;
    if (k == N) continue;
    c.key = spec[k].key;
    if (seen & (std::uint64_t{1} << k)) c.parse_fail("the key once per object (it repeats)");
    seen |= std::uint64_t{1} << k;
    od::value& value = field.value();
    spec[k].read(value, c, r);
  }
  for (size_t k = 0; k < N; ++k) {
    if (spec[k].required && !(seen & (std::uint64_t{1} << k))) {
      c.key = spec[k].key;
      c.parse_fail("this required key (missing)");
    }
  }
  c.key = {};
}

template <class R, size_t N>
void read_object(od::value& v, Ctx& c, const std::array<Field<R>, N>& spec, R& r) {
  od::object object;
  if (auto ec = v.get_object().get(object)) c.parse_fail("a JSON object", ec);
  read_fields(object, c, spec, r);
}

// Records with a "token": it is read first so that an error in any other field, whatever
// the key order, names the record.
template <class R, size_t N>
void read_record(od::value& v, Ctx& c, const std::array<Field<R>, N>& spec, R& r) {
  od::object object;
  if (auto ec = v.get_object().get(object)) c.parse_fail("a JSON object", ec);
  od::value token_value;
  c.key = "token";
  const auto ec = object.find_field_unordered("token").get(token_value);
  if (ec == simdjson::NO_SUCH_FIELD) c.parse_fail("this required key (missing)");
  if (ec) c.parse_fail("a JSON object with a \"token\"", ec);
  r.token = std::string(get_token(token_value, c));
  c.token = r.token;
  c.key = {};
  bool is_empty = false;
  if (auto rec = object.reset().get(is_empty)) c.parse_fail("a JSON object", rec);
  read_fields(object, c, spec, r);
}
template <class R, std::string R::*M>
void token_field(od::value& v, Ctx& c, R& r) {
  r.*M = std::string(get_token(v, c));
}
template <class R, std::vector<std::string> R::*M>
void token_list_field(od::value& v, Ctx& c, R& r) {
  r.*M = get_token_list(v, c);
}

}  // namespace nsg::nuscenes::map_detail
