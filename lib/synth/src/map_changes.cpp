// changes.json (changes.h, schemas/v1/synth-changes.schema.json): its one writer and its one
// reader. A release is shared and unpacked from archives, so the reader takes the file as a
// stranger's: the size is bounded before reading, the nesting while parsing, and every field
// is checked to the schema's rules (the map paths are the two the writer makes, so nothing
// read here can point outside the release).
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "nsg/core/bounded_file.h"
#include "nsg/core/error.h"
#include "nsg/core/json.h"
#include "nsg/core/strings.h"
#include "nsg/synth/changes.h"

namespace nsg::synth {

namespace {

using Json = nlohmann::json;

constexpr int kMaxDepth = 6;  // root → edits → edit → at_m → number
constexpr double kMaxAbsCoordinateM = 1e7;
const char* const kKind = "nsgraph-synth-changes";

std::string prior_map_of(const std::string& location) { return "maps/prior/expansion/" + location + ".json"; }
std::string current_map_of(const std::string& location) { return "maps/expansion/" + location + ".json"; }

bool is_location(const std::string& s) {
  return s == "singapore-onenorth" || s == "singapore-hollandvillage" || s == "singapore-queenstown" ||
         s == "boston-seaport";
}
bool is_date(const std::string& s) {
  if (s.size() != 10 || s[4] != '-' || s[7] != '-') return false;
  for (size_t i = 0; i < s.size(); ++i)
    if (i != 4 && i != 7 && (s[i] < '0' || s[i] > '9')) return false;
  return true;
}
bool is_token(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (const char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || c == '-')) return false;
  return true;
}

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  MapChanges read(const Json& doc) {
    object(doc, "", {"schema_version", "kind", "location", "from_day", "date", "prior_map", "current_map", "edits"});
    text(doc, "/schema_version", "\"1\"", [](const std::string& s) { return s == "1"; });
    text(doc, "/kind", std::string("\"") + kKind + "\"", [](const std::string& s) { return s == kKind; });
    MapChanges c;
    c.location = text(doc, "/location", "one of the four nuScenes locations", is_location);
    const Json& day = doc["from_day"];
    if (!day.is_number_integer() || day.get<int64_t>() < 1 || day.get<int64_t>() > 364)
      fail("/from_day", "an integer in [1, 364]");
    c.from_day = static_cast<int>(day.get<int64_t>());
    c.date = text(doc, "/date", "a date YYYY-MM-DD", is_date);
    c.prior_map = text(doc, "/prior_map", "\"" + prior_map_of(c.location) + "\"",
                       [&](const std::string& s) { return s == prior_map_of(c.location); });
    c.current_map = text(doc, "/current_map", "\"" + current_map_of(c.location) + "\"",
                         [&](const std::string& s) { return s == current_map_of(c.location); });
    const Json& edits = doc["edits"];
    if (!edits.is_array() || edits.size() > kMaxMapEdits)
      fail("/edits", strprintf("an array of at most %zu edits", kMaxMapEdits));
    for (size_t i = 0; i < edits.size(); ++i) c.edits.push_back(edit(edits[i], "/edits/" + std::to_string(i)));
    return c;
  }

 private:
  [[noreturn]] void fail(const std::string& at, const std::string& expected) const {
    throw ParseError(file_, at.empty() ? "/" : at, expected);
  }

  void object(const Json& v, const std::string& at, const std::set<std::string>& keys) const {
    if (!v.is_object()) fail(at, "an object");
    for (const std::string& k : keys)
      if (!v.contains(k)) fail(at + "/" + k, "a member '" + k + "'");
    for (const auto& [k, _] : v.items())
      if (!keys.count(k)) fail(at + "/" + printable_text(k), "no such member (the schema allows none but the listed)");
  }

  template <class Ok>
  std::string text(const Json& parent, const std::string& at, const std::string& expected, Ok&& ok) const {
    const Json& v = parent[at.substr(at.rfind('/') + 1)];
    if (!v.is_string() || !ok(v.get<std::string>())) fail(at, expected);
    return v.get<std::string>();
  }

  std::vector<std::string> tokens(const Json& v, const std::string& at) const {
    if (!v.is_array() || v.size() > kMaxTokensPerEdit)
      fail(at, strprintf("an array of at most %zu map tokens", kMaxTokensPerEdit));
    std::vector<std::string> out;
    for (size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_string() || !is_token(v[i].get<std::string>()))
        fail(at + "/" + std::to_string(i), "a map token (1-64 characters of 0-9, a-f, '-')");
      out.push_back(v[i].get<std::string>());
    }
    return out;
  }

  MapEdit edit(const Json& v, const std::string& at) const {
    object(v, at, {"kind", "removed", "added", "retyped", "at_m"});
    MapEdit e;
    e.kind = text(v, at + "/kind", "one of lane_closed, turn_removed, turn_added, divider_retyped, crossing_added",
                  [](const std::string& s) {
                    for (const char* k : kMapEditKinds)
                      if (s == k) return true;
                    return false;
                  });
    e.removed = tokens(v["removed"], at + "/removed");
    e.added = tokens(v["added"], at + "/added");
    e.retyped = tokens(v["retyped"], at + "/retyped");
    const Json& p = v["at_m"];
    if (!p.is_array() || p.size() != 2) fail(at + "/at_m", "[x, y] in metres");
    for (size_t k = 0; k < 2; ++k) {
      if (!p[k].is_number() || !std::isfinite(p[k].get<double>()) || std::fabs(p[k].get<double>()) > kMaxAbsCoordinateM)
        fail(at + "/at_m/" + std::to_string(k), "a finite coordinate within 1e7 m");
      e.at_m[k] = p[k].get<double>();
    }
    return e;
  }

  std::string file_;
};

}  // namespace

std::string map_changes_text(const MapChanges& c) {
  nlohmann::ordered_json edits = nlohmann::ordered_json::array();
  for (const MapEdit& e : c.edits)
    edits.push_back(
        {{"kind", e.kind}, {"removed", e.removed}, {"added", e.added}, {"retyped", e.retyped}, {"at_m", e.at_m}});
  const nlohmann::ordered_json doc = {{"schema_version", "1"},
                                      {"kind", kKind},
                                      {"location", c.location},
                                      {"from_day", c.from_day},
                                      {"date", c.date},
                                      {"prior_map", prior_map_of(c.location)},
                                      {"current_map", current_map_of(c.location)},
                                      {"edits", edits}};
  return doc.dump(1) + "\n";
}

MapChanges read_map_changes(const std::filesystem::path& file) {
  const std::string text = read_file_within(file, kMaxMapChangesBytes, "changes.json of nsgraph synth");
  const Json doc = parse_json_strict(text, file.string(), "changes.json of nsgraph synth", kMaxDepth);
  return Reader(file.string()).read(doc);
}

}  // namespace nsg::synth
