// The done-record's one writer and one reader (nsg/pipeline/done_record.h).
#include "nsg/pipeline/done_record.h"

#include "nsg/core/bounded_file.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/strings.h"
#include "nsg/validate/submission.h"  // json_pointer_token

namespace nsg::pipeline {

using nlohmann::ordered_json;

ordered_json done_item_json(const DoneItem& item) {
  ordered_json files = ordered_json::array();
  for (const DoneFile& f : item.files) files.push_back({{"file", f.file}, {"sha256", f.sha256}, {"bytes", f.bytes}});
  ordered_json out = {{"id", item.id}, {"kind", item.kind}, {"location", item.location}};
  if (item.kind == "shard") {
    out["split"] = item.split;
    out["shard"] = item.shard;
    out["tiles"] = item.tiles;
  }
  out["files"] = std::move(files);
  out["digest"] = item.digest;
  return out;
}

std::string done_record_text(const DoneRecord& record) {
  ordered_json items = ordered_json::array();
  for (const DoneItem& item : record.items) items.push_back(done_item_json(item));
  const ordered_json doc = {{"schema_version", "1"},
                            {"tool_version", record.tool_version},
                            {"share", {{"index", record.share_index}, {"count", record.share_count}}},
                            {"config_sha256", record.config_sha256},
                            {"config", record.config_json},
                            {"complete", record.complete},
                            {"plan", record.plan_json},
                            {"items", std::move(items)}};
  return doc.dump(1) + "\n";
}

namespace {

// `text` cut to `max_chars` (with "…"), for a message.
std::string shortened(const std::string& text, size_t max_chars) {
  return text.size() <= max_chars ? text : text.substr(0, max_chars) + "…";
}

// The JSON pointer of the first member where `got` differs from `want` ("" when equal),
// objects compared member by member whatever their order.
std::string first_difference(const ordered_json& want, const ordered_json& got, const std::string& at) {
  if (want.is_object() && got.is_object()) {
    for (const auto& [key, value] : want.items()) {
      const auto it = got.find(key);
      if (it == got.end()) return at + "/" + validate::json_pointer_token(key);
      const std::string d = first_difference(value, *it, at + "/" + validate::json_pointer_token(key));
      if (!d.empty()) return d;
    }
    for (const auto& [key, value] : got.items())
      if (!want.contains(key)) return at + "/" + validate::json_pointer_token(key);
    return "";
  }
  if (want.is_array() && got.is_array()) {
    if (want.size() != got.size()) return at;
    for (size_t i = 0; i < want.size(); ++i) {
      const std::string d = first_difference(want[i], got[i], at + "/" + std::to_string(i));
      if (!d.empty()) return d;
    }
    return "";
  }
  return want == got ? "" : at;  // member order is not compared: JSON objects have none
}

// Field checks of one record: ParseError naming the file and the JSON pointer. Each helper
// takes the object, its pointer in the record and the member's name.
class RecordReader {
 public:
  explicit RecordReader(std::string file) : file_(std::move(file)) {}

  DoneRecord read(const ordered_json& d) {
    need(d.is_object(), "", "a done-record object");
    DoneRecord r;
    need(text(d, "", "schema_version") == "1", "/schema_version", "\"1\"");
    r.tool_version = text(d, "", "tool_version");
    const ordered_json& share = member(d, "", "share");
    need(share.is_object(), "/share", "{\"index\", \"count\"}");
    r.share_count = static_cast<int>(integer(share, "/share", "count", 1, 1'000'000));
    r.share_index = static_cast<int>(integer(share, "/share", "index", 0, r.share_count - 1));
    r.config_sha256 = text(d, "", "config_sha256");
    r.complete = boolean(d, "", "complete");
    r.config_json = member(d, "", "config");
    need(r.config_json.is_object(), "/config", "the run's config object");
    try {
      r.config = config_from_json(nlohmann::json(r.config_json), file_ + ":/config");
    } catch (const ConfigError& e) {
      throw ParseError(file_, "/config", "a generate config (" + e.record() + ": " + e.expected() + ")");
    }
    // Resolved and whole, as generate writes it: merge copies it into the manifest.
    const ordered_json resolved = config_to_json(r.config);
    const std::string differs = first_difference(resolved, r.config_json, "/config");
    if (!differs.empty()) {
      const ordered_json::json_pointer at(differs.substr(std::string("/config").size()));
      const std::string want = resolved.contains(at) ? resolved.at(at).dump() : "(absent)";
      const std::string got = r.config_json.contains(at) ? r.config_json.at(at).dump() : "(absent)";
      need(false, differs,
           "the run's resolved config as generate writes it (every member): " + printable_text(shortened(want, 200)) +
               ", got " + printable_text(shortened(got, 200)));
    }
    r.plan_json = member(d, "", "plan");
    need(r.plan_json.is_array(), "/plan", "an array of locations");
    need(r.complete || r.plan_json.empty(), "/plan", "[] while the share is not complete");
    r.plan = io::manifest_locations_from_json(r.plan_json, file_, "/plan");
    const ordered_json& items = member(d, "", "items");
    need(items.is_array(), "/items", "an array");
    for (size_t i = 0; i < items.size(); ++i) r.items.push_back(item(items[i], "/items/" + std::to_string(i)));
    return r;
  }

 private:
  void need(bool ok, const std::string& at, const std::string& what) const {
    NSG_CHECK(ok, ParseError, file_, at, what);
  }
  const ordered_json& member(const ordered_json& o, const std::string& at, const char* name) const {
    const auto it = o.find(name);
    need(it != o.end(), at + "/" + name, "a value (missing)");
    return *it;
  }
  std::string text(const ordered_json& o, const std::string& at, const char* name) const {
    const ordered_json& v = member(o, at, name);
    need(v.is_string(), at + "/" + name, "a string");
    return v.get<std::string>();
  }
  bool boolean(const ordered_json& o, const std::string& at, const char* name) const {
    const ordered_json& v = member(o, at, name);
    need(v.is_boolean(), at + "/" + name, "true or false");
    return v.get<bool>();
  }
  int64_t integer(const ordered_json& o, const std::string& at, const char* name, int64_t lo, int64_t hi) const {
    const ordered_json& v = member(o, at, name);
    const bool in_range =
        (v.is_number_unsigned() && v.get<uint64_t>() <= static_cast<uint64_t>(hi) && lo >= 0) ||
        (v.is_number_integer() && !v.is_number_unsigned() && v.get<int64_t>() >= lo && v.get<int64_t>() <= hi);
    need(in_range && v.get<int64_t>() >= lo, at + "/" + name,
         "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v.get<int64_t>();
  }

  DoneItem item(const ordered_json& e, const std::string& at) const {
    need(e.is_object(), at, "an item object");
    DoneItem it;
    it.id = text(e, at, "id");
    it.kind = text(e, at, "kind");
    need(it.kind == "maps" || it.kind == "shard", at + "/kind", "\"maps\" or \"shard\"");
    it.location = text(e, at, "location");
    if (it.kind == "shard") {
      it.split = text(e, at, "split");
      it.shard = text(e, at, "shard");
      it.tiles = integer(e, at, "tiles", 0, int64_t{1} << 40);
    }
    const ordered_json& files = member(e, at, "files");
    need(files.is_array(), at + "/files", "an array");
    for (size_t k = 0; k < files.size(); ++k) {
      const std::string fat = at + "/files/" + std::to_string(k);
      const ordered_json& f = files[k];
      need(f.is_object(), fat, "a file object");
      DoneFile df{text(f, fat, "file"), text(f, fat, "sha256"), integer(f, fat, "bytes", 0, int64_t{1} << 50)};
      need(stays_inside(df.file), fat + "/file",
           "a path inside the dataset folder, got '" + printable_text(df.file) + "'");
      it.files.push_back(std::move(df));
    }
    it.digest = text(e, at, "digest");
    return it;
  }

  std::string file_;
};

}  // namespace

DoneRecord done_record_from_text(std::string_view text, const std::filesystem::path& file) {
  // Strict first (nesting, repeated keys: a record is an outside file like any other), then
  // in order (the plan's order is the manifest's).
  parse_json_strict(text, file.string(), "a done-record", kMaxDoneRecordDepth);
  try {
    DoneRecord r = RecordReader(file.string()).read(ordered_json::parse(text));
    r.path = file;
    return r;
  } catch (const nlohmann::json::exception& e) {
    // Every field is checked before it is read; this is the net under that rule.
    throw ParseError(file.string(), "", std::string("a done-record as generate writes it (") + e.what() + ")");
  }
}

DoneRecord read_done_record(const std::filesystem::path& path) {
  return done_record_from_text(read_file_within(path, kMaxDoneRecordBytes, "a done-record"), path);
}

}  // namespace nsg::pipeline
