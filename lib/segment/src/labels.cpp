#include "nsg/segment/labels.h"

#include <algorithm>
#include <charconv>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/validate/documents.h"
#include "nsg/validate/schema.h"

namespace nsg::segment {

namespace fs = std::filesystem;

const std::vector<std::string>& class_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const SemanticClassInfo& c : kSemanticClasses) out.emplace_back(c.name);
    return out;
  }();
  return names;
}

std::array<uint8_t, 256> SegmentLabels::table() const {
  std::array<uint8_t, 256> t;
  t.fill(kVoid);
  for (size_t c = 0; c < class_of_channel.size() && c < t.size(); ++c) t[c] = class_of_channel[c];
  return t;
}

namespace {

uint8_t class_id(const std::string& name, const std::string& file_label, const std::string& pointer) {
  if (name == "void") return kVoid;
  const auto& names = class_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<uint8_t>(it - names.begin());
  std::string list;
  for (const std::string& n : names) list += n + ", ";
  throw ParseError(file_label, pointer,
                   "one of our classes (samples/semantic-classes.json: " + list + "or void), got \"" + name + "\"");
}

ModelInput input_from_json(const nlohmann::json& j) {
  ModelInput in;
  in.width = j.at("width").get<int>();
  in.height = j.at("height").get<int>();
  in.rgb = j.value("rgb", true);
  in.scale = j.value("scale", 1.0 / 255.0);
  if (j.contains("mean")) in.mean = j["mean"].get<std::array<double, 3>>();
  if (j.contains("std")) in.std = j["std"].get<std::array<double, 3>>();
  return in;
}

SegmentLabels build_labels(const nlohmann::json& doc, const std::string& file_label) {
  SegmentLabels labels;
  labels.file = file_label;
  if (doc.contains("input")) labels.input = input_from_json(doc["input"]);
  int max_channel = -1;
  std::vector<std::pair<int, uint8_t>> entries;
  for (const auto& [key, value] : doc.at("classes").items()) {
    const std::string pointer = "/classes/" + key;
    int channel = -1;
    const auto [end, ec] = std::from_chars(key.data(), key.data() + key.size(), channel);
    // The schema's pattern already says so; kept for documents checked without it.
    if (ec != std::errc() || end != key.data() + key.size() || channel < 0 || channel > 4095)
      throw ParseError(file_label, pointer, "a channel index 0..4095 as the key");
    entries.push_back({channel, class_id(value.get<std::string>(), file_label, pointer)});
    max_channel = std::max(max_channel, channel);
  }
  labels.class_of_channel.assign(static_cast<size_t>(max_channel + 1), kVoid);
  for (const auto& [channel, cls] : entries) labels.class_of_channel[static_cast<size_t>(channel)] = cls;
  return labels;
}

}  // namespace

SegmentLabels labels_from_json(const nlohmann::json& doc, const std::string& file_label, const fs::path& schemas_dir) {
  const fs::path schema = validate::schema_path("segment-labels", schemas_dir);
  const Issues issues = validate::validate_against_schema(schema, doc, file_label, "segment.labels");
  if (!issues.items().empty()) {
    const Issue& first = issues.items().front();
    // The subject is "<file_label>:<JSON pointer>"; the error names the file once.
    const std::string pointer =
        first.subject.rfind(file_label + ":", 0) == 0 ? first.subject.substr(file_label.size() + 1) : first.subject;
    throw ParseError(file_label, pointer, "a labels file as schemas/v1/segment-labels.schema.json: " + first.message);
  }
  return build_labels(doc, file_label);
}

SegmentLabels load_labels(const fs::path& file, const fs::path& schemas_dir) {
  // Strict: a class named twice in one object would keep only its last mapping.
  const nlohmann::json doc = parse_json_strict(read_file(file), file.string(), "a JSON labels file");
  return labels_from_json(doc, file.string(), schemas_dir);
}

const SegmentLabels& builtin_lidarseg_labels() {
  // Index → our class; see samples/semantic-labels/nuscenes-lidarseg.json for the reasons.
  static const SegmentLabels labels = [] {
    const char* kClasses[32] = {"void",        "void",      "person",     "person", "person",    "person",    "person",
                                "person",      "person",    "void",       "void",   "void",      "void",      "void",
                                "two_wheeler", "truck_bus", "truck_bus",  "car",    "truck_bus", "truck_bus", "car",
                                "two_wheeler", "truck_bus", "truck_bus",  "road",   "void",      "sidewalk",  "terrain",
                                "building",    "void",      "vegetation", "void"};
    nlohmann::json doc = {{"schema_version", "1"}, {"classes", nlohmann::json::object()}};
    for (int i = 0; i < 32; ++i) doc["classes"][std::to_string(i)] = kClasses[i];
    return build_labels(doc, "built-in nuscenes-lidarseg labels");
  }();
  return labels;
}

}  // namespace nsg::segment
