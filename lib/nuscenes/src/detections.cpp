#include "nsg/nuscenes/detections.h"

#include <cmath>

#include "json_reader.h"
#include "nsg/core/error.h"
#include "nsg/nuscenes/database.h"

namespace nsg::nuscenes {

namespace {

constexpr std::array<const char*, kDetectionClassCount> kClassNames = {
    "car",        "truck",      "bus",     "trailer",      "construction_vehicle",
    "pedestrian", "motorcycle", "bicycle", "traffic_cone", "barrier"};

using detail::FieldSpec;
using detail::RecordContext;
using detail::od::value;

#define NSG_FIELD(R, key, body)                           \
  FieldSpec<R> {                                          \
    key, [](value& v, RecordContext& ctx, R& r) { body; } \
  }
#define NSG_OPTIONAL_FIELD(R, key, body)                         \
  FieldSpec<R> {                                                 \
    key, [](value& v, RecordContext& ctx, R& r) { body; }, false \
  }

DetectionClass read_class(value& v, const RecordContext& ctx) {
  const std::string_view s = detail::read_string(v, ctx);
  const std::optional<DetectionClass> c = parse_detection_class(s);
  if (!c) ctx.fail("one of the 10 detection classes (car, truck, …, barrier), got \"" + std::string(s) + "\"");
  return *c;
}

double read_score(value& v, const RecordContext& ctx) {
  const double s = detail::read_double(v, ctx);
  if (!(s >= 0.0 && s <= 1.0)) ctx.fail("a detection score in [0, 1]");
  return s;
}

std::array<double, 3> read_size(value& v, const RecordContext& ctx) {
  const std::array<double, 3> s = detail::read_numbers<3>(v, ctx);
  if (s[0] < 0.0 || s[1] < 0.0 || s[2] < 0.0) ctx.fail("a non-negative size [w, l, h]");
  return s;
}

constexpr std::array kBoxFields{
    NSG_FIELD(DetectionBox, "sample_token", r.sample_token = detail::read_token(v, ctx)),
    NSG_FIELD(DetectionBox, "translation", r.translation = detail::read_numbers<3>(v, ctx)),
    NSG_FIELD(DetectionBox, "size", r.size = read_size(v, ctx)),
    NSG_FIELD(DetectionBox, "rotation", r.rotation = detail::read_quaternion(v, ctx)),
    NSG_FIELD(DetectionBox, "velocity", r.velocity = detail::read_numbers<2>(v, ctx)),
    NSG_FIELD(DetectionBox, "detection_name", r.detection_name = read_class(v, ctx)),
    NSG_FIELD(DetectionBox, "detection_score", r.detection_score = read_score(v, ctx)),
    NSG_FIELD(DetectionBox, "attribute_name", r.attribute_name = detail::read_string(v, ctx)),
    NSG_OPTIONAL_FIELD(DetectionBox, "ego_translation", r.ego_translation = detail::read_numbers<3>(v, ctx)),
    NSG_OPTIONAL_FIELD(DetectionBox, "num_pts", r.num_pts = detail::read_int32(v, ctx)),
};

constexpr std::array kMetaFields{
    NSG_FIELD(DetectionMeta, "use_camera", r.use_camera = detail::read_bool(v, ctx)),
    NSG_FIELD(DetectionMeta, "use_lidar", r.use_lidar = detail::read_bool(v, ctx)),
    NSG_FIELD(DetectionMeta, "use_radar", r.use_radar = detail::read_bool(v, ctx)),
    NSG_FIELD(DetectionMeta, "use_map", r.use_map = detail::read_bool(v, ctx)),
    NSG_FIELD(DetectionMeta, "use_external", r.use_external = detail::read_bool(v, ctx)),
};

#undef NSG_FIELD
#undef NSG_OPTIONAL_FIELD

void read_sample_boxes(value& boxes_value, RecordContext& ctx, DetectionSample& sample) {
  detail::od::array boxes;
  if (auto ec = boxes_value.get_array().get(boxes)) ctx.fail("an array of boxes", ec);
  size_t index = 0;
  for (auto element : boxes) {
    ctx.index = index;
    ctx.key = {};
    if (index == kMaxBoxesPerSample) ctx.fail("at most 500 boxes per sample");
    detail::od::object object;
    if (auto ec = element.get_object().get(object)) ctx.fail("a box object", ec);
    DetectionBox& box = sample.boxes.emplace_back();
    detail::read_record(object, ctx, kBoxFields, box);
    if (box.sample_token != sample.sample_token) {
      ctx.key = "sample_token";
      ctx.fail("the box's sample_token to equal its results key, got " + box.sample_token.str());
    }
    if (!attribute_valid_for(box.detection_name, box.attribute_name)) {
      ctx.key = "attribute_name";
      ctx.fail("\"\" or an attribute valid for class " + std::string(detection_class_name(box.detection_name)) +
               ", got \"" + box.attribute_name + "\"");
    }
    ++index;
  }
}

void read_results(value& results_value, RecordContext& ctx, DetectionResults& out) {
  detail::od::object results;
  if (auto ec = results_value.get_object().get(results))
    ctx.fail("\"results\" to be an object {sample_token: [boxes]}", ec);
  for (auto field_result : results) {
    detail::od::field field;
    ctx.record_prefix = "results";
    ctx.index = out.samples.size();
    ctx.key = {};
    if (auto ec = std::move(field_result).get(field)) ctx.fail("a sample_token key", ec);
    std::string_view key;
    if (auto ec = field.unescaped_key().get(key)) ctx.fail("a sample_token key", ec);
    const std::optional<Token> token = Token::parse(key);
    if (!token || token->empty())
      ctx.fail("a sample token of 32 lowercase hex chars as key, got \"" + std::string(key) + "\"");
    DetectionSample& sample = out.samples.emplace_back();
    sample.sample_token = *token;
    ctx.record_prefix = "results[" + token->str() + "] box";
    detail::od::value boxes = field.value();
    read_sample_boxes(boxes, ctx, sample);
  }
  ctx.record_prefix.clear();
}

}  // namespace

const char* detection_class_name(DetectionClass c) { return kClassNames[static_cast<size_t>(c)]; }

std::optional<DetectionClass> parse_detection_class(std::string_view name) {
  for (size_t i = 0; i < kClassNames.size(); ++i) {
    if (name == kClassNames[i]) return static_cast<DetectionClass>(i);
  }
  return std::nullopt;
}

bool attribute_valid_for(DetectionClass c, std::string_view a) {
  if (a.empty()) return true;
  switch (c) {
    case DetectionClass::kCar:
    case DetectionClass::kTruck:
    case DetectionClass::kBus:
    case DetectionClass::kTrailer:
    case DetectionClass::kConstructionVehicle:
      return a == "vehicle.moving" || a == "vehicle.parked" || a == "vehicle.stopped";
    case DetectionClass::kPedestrian:
      return a == "pedestrian.moving" || a == "pedestrian.standing" || a == "pedestrian.sitting_lying_down";
    case DetectionClass::kMotorcycle:
    case DetectionClass::kBicycle: return a == "cycle.with_rider" || a == "cycle.without_rider";
    case DetectionClass::kTrafficCone:
    case DetectionClass::kBarrier: return false;
  }
  return false;
}

std::optional<DetectionClass> detection_class_of_category(std::string_view n) {
  if (n == "vehicle.car") return DetectionClass::kCar;
  if (n == "vehicle.truck") return DetectionClass::kTruck;
  if (n == "vehicle.bus.bendy" || n == "vehicle.bus.rigid") return DetectionClass::kBus;
  if (n == "vehicle.trailer") return DetectionClass::kTrailer;
  if (n == "vehicle.construction") return DetectionClass::kConstructionVehicle;
  if (n == "human.pedestrian.adult" || n == "human.pedestrian.child" || n == "human.pedestrian.construction_worker" ||
      n == "human.pedestrian.police_officer") {
    return DetectionClass::kPedestrian;
  }
  if (n == "vehicle.motorcycle") return DetectionClass::kMotorcycle;
  if (n == "vehicle.bicycle") return DetectionClass::kBicycle;
  if (n == "movable_object.trafficcone") return DetectionClass::kTrafficCone;
  if (n == "movable_object.barrier") return DetectionClass::kBarrier;
  return std::nullopt;
}

bool is_vehicle_class(DetectionClass c) {
  return c == DetectionClass::kCar || c == DetectionClass::kTruck || c == DetectionClass::kBus ||
         c == DetectionClass::kTrailer || c == DetectionClass::kConstructionVehicle;
}

Index DetectionResults::find(const Token& sample_token) const {
  return index.find(sample_token, [&](size_t i) -> const Token& { return samples[i].sample_token; });
}

DetectionResults read_detections(const std::filesystem::path& file) {
  DetectionResults out;
  out.file = file.string();
  simdjson::padded_string json = detail::load_padded(file);
  detail::od::parser parser;
  RecordContext ctx;
  ctx.file = out.file;
  detail::od::document doc;
  if (auto ec = parser.iterate(json).get(doc)) ctx.fail("a JSON document", ec);
  detail::od::object root;
  if (auto ec = doc.get_object().get(root)) ctx.fail("a JSON object {\"meta\", \"results\"}", ec);
  bool has_meta = false, has_results = false;
  for (auto field_result : root) {
    detail::od::field field;
    if (auto ec = std::move(field_result).get(field)) ctx.fail("a key/value pair", ec);
    std::string_view key;
    if (auto ec = field.unescaped_key().get(key)) ctx.fail("a string key", ec);
    detail::od::value v;
    if (key == "meta" || key == "results") {
      bool& seen = key == "meta" ? has_meta : has_results;
      ctx.record_prefix = std::string(key);
      if (seen) ctx.fail("the key once");
      seen = true;
      v = field.value();
      if (key == "meta") {
        detail::od::object meta;
        if (auto ec = v.get_object().get(meta)) ctx.fail("\"meta\" to be an object", ec);
        ctx.record_prefix = "meta";
        detail::read_record(meta, ctx, kMetaFields, out.meta);
      } else {
        read_results(v, ctx, out);
      }
      ctx.record_prefix.clear();
    }
  }
  if (!detail::at_end(doc)) ctx.fail("end of file after the top-level object");
  if (!has_meta) throw ParseError(out.file, "", "required key \"meta\" (missing)");
  if (!has_results) throw ParseError(out.file, "", "required key \"results\" (missing)");
  const Index dup =
      out.index.build(out.samples.size(), [&](size_t i) -> const Token& { return out.samples[i].sample_token; });
  if (dup != kNoIndex) {
    throw ParseError(out.file, "results[" + out.samples[static_cast<size_t>(dup)].sample_token.str() + "]",
                     "each sample token once in \"results\"");
  }
  return out;
}

void check_covers(const DetectionResults& results, const Database& db, std::span<const Index> sample_indices) {
  std::vector<char> wanted(results.samples.size(), 0);
  for (Index s : sample_indices) {
    const Token& token = db.sample[s].token;
    const Index row = results.find(token);
    if (row == kNoIndex) {
      throw DataError(results.file, "results[" + token.str() + "]",
                      "every sample of the evaluated set (this sample is missing; an empty list is allowed)");
    }
    wanted[static_cast<size_t>(row)] = 1;
  }
  for (size_t i = 0; i < wanted.size(); ++i) {
    if (!wanted[i]) {
      throw DataError(results.file, "results[" + results.samples[i].sample_token.str() + "]",
                      "only samples of the evaluated set (this sample is not in it)");
    }
  }
}

void check_covers(const DetectionResults& results, const Database& db) {
  std::vector<Index> all(db.sample.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<Index>(i);
  check_covers(results, db, all);
}

void check_known_samples(const DetectionResults& results, const Database& db) {
  for (const DetectionSample& sample : results.samples) {
    if (db.sample.find(sample.sample_token) == kNoIndex) {
      throw DataError(results.file, "results[" + sample.sample_token.str() + "]",
                      "a sample token of the release " + db.version() + " (" + db.sample.file() +
                          " has no such sample; is this a results file of another release?)");
    }
  }
}

}  // namespace nsg::nuscenes
