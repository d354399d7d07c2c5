// Table readers: one declarative field list per table (docs/nuscenes-input.md).
#include "nsg/nuscenes/tables.h"

#include <cstring>
#include <limits>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "json_reader.h"
#include "nsg/core/error.h"

namespace nsg::nuscenes {

// ---------------------------------------------------------------------------------- Token

namespace {

#if defined(__SSE2__)
// 16 lowercase hex characters → 8 bytes (SSE2, baseline on x86-64); false if one is not
// [0-9a-f]. A table record holds ~6 tokens, so this runs millions of times per table.
bool hex16_to_bytes(const char* text, std::uint8_t* out) {
  const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(text));
  const __m128i digit = _mm_sub_epi8(c, _mm_set1_epi8('0'));                              // 0..9 for '0'..'9'
  const __m128i letter = _mm_sub_epi8(c, _mm_set1_epi8('a'));                             // 0..5 for 'a'..'f'
  const __m128i is_digit = _mm_cmpeq_epi8(_mm_min_epu8(digit, _mm_set1_epi8(9)), digit);  // unsigned ≤ 9
  const __m128i is_letter = _mm_cmpeq_epi8(_mm_min_epu8(letter, _mm_set1_epi8(5)), letter);
  if (_mm_movemask_epi8(_mm_or_si128(is_digit, is_letter)) != 0xffff) return false;
  const __m128i nibble =
      _mm_or_si128(_mm_and_si128(is_digit, digit), _mm_andnot_si128(is_digit, _mm_add_epi8(letter, _mm_set1_epi8(10))));
  // 16-bit lanes hold (second << 8 | first); a byte is (first << 4) | second.
  const __m128i pairs =
      _mm_or_si128(_mm_slli_epi16(_mm_and_si128(nibble, _mm_set1_epi16(0x00ff)), 4), _mm_srli_epi16(nibble, 8));
  _mm_storel_epi64(reinterpret_cast<__m128i*>(out), _mm_packus_epi16(pairs, pairs));
  return true;
}
#endif

}  // namespace

std::optional<Token> Token::parse(std::string_view text, bool allow_short) {
  Token t;
  if (text.empty()) return t;
#if defined(__SSE2__)
  if (text.size() == 32) {
    if (hex16_to_bytes(text.data(), t.bytes_.data()) && hex16_to_bytes(text.data() + 16, t.bytes_.data() + 8)) {
      t.kind_ = Kind::kHex32;
      return t;
    }
    t.bytes_ = {};
  }
#else
  if (text.size() == 32) {
    // SWAR: 8 chars per step; lowercase hex only (this runs ~6 times per table record).
    constexpr std::uint64_t kL = 0x0101010101010101ULL, kH = 0x8080808080808080ULL;
    bool ok = true;
    for (size_t w = 0; w < 4; ++w) {
      std::uint64_t x;
      std::memcpy(&x, text.data() + 8 * w, 8);  // little-endian: char 0 in the low byte
      const auto ge = [&](std::uint64_t lo) { return ((x | kH) - kL * lo) & kH; };      // byte >= lo
      const auto le = [&](std::uint64_t hi) { return ((kL * (0x80 + hi)) - x) & kH; };  // byte <= hi
      const std::uint64_t digit = ge(0x30) & le(0x39), letter = ge(0x61) & le(0x66);
      ok &= ((x & kH) == 0) & ((digit | letter) == kH);
      const std::uint64_t nibbles = (x & (kL * 0x0F)) + (letter >> 7) * 9;
      std::uint64_t v = ((nibbles << 4) | (nibbles >> 8)) & 0x00FF00FF00FF00FFULL;  // pairs in even bytes
      v = (v | (v >> 8)) & 0x0000FFFF0000FFFFULL;
      v = (v | (v >> 16)) & 0x00000000FFFFFFFFULL;
      const std::uint32_t packed = static_cast<std::uint32_t>(v);
      std::memcpy(t.bytes_.data() + 4 * w, &packed, 4);
    }
    if (ok) {
      t.kind_ = Kind::kHex32;
      return t;
    }
    t.bytes_ = {};
  }
#endif
  if (!allow_short || text.size() > kMaxShortLength) return std::nullopt;
  for (char c : text) {
    if (c <= ' ' || c > '~') return std::nullopt;
  }
  t.kind_ = Kind::kShort;
  t.length_ = static_cast<std::uint8_t>(text.size());
  std::memcpy(t.bytes_.data(), text.data(), text.size());
  return t;
}

Token Token::from_string(std::string_view text) {
  const std::optional<Token> t = parse(text, true);
  if (!t) throw std::invalid_argument("not a token: " + std::string(text));
  return *t;
}

std::string Token::str() const {
  switch (kind_) {
    case Kind::kEmpty: return {};
    case Kind::kShort: return std::string(reinterpret_cast<const char*>(bytes_.data()), length_);
    case Kind::kHex32: break;
  }
  static const char* kDigits = "0123456789abcdef";
  std::string s(32, '0');
  for (size_t i = 0; i < 16; ++i) {
    s[2 * i] = kDigits[bytes_[i] >> 4];
    s[2 * i + 1] = kDigits[bytes_[i] & 15];
  }
  return s;
}

std::uint64_t Token::hash() const {
  std::uint64_t a = 0, b = 0;
  std::memcpy(&a, bytes_.data(), 8);
  std::memcpy(&b, bytes_.data() + 8, 8);
  // splitmix64 finaliser: hex tokens are random already, short ones are not.
  std::uint64_t h = a ^ (b * 0x9e3779b97f4a7c15ULL) ^ (static_cast<std::uint64_t>(length_) << 56);
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebULL;
  h ^= h >> 31;
  return h;
}

bool operator<(const Token& a, const Token& b) {
  if (a.kind_ != b.kind_) return a.kind_ < b.kind_;
  if (a.length_ != b.length_) return a.length_ < b.length_;
  return std::memcmp(a.bytes_.data(), b.bytes_.data(), 16) < 0;
}

const char* modality_name(Modality m) {
  switch (m) {
    case Modality::kCamera: return "camera";
    case Modality::kLidar: return "lidar";
    case Modality::kRadar: return "radar";
  }
  return "?";
}

// ---------------------------------------------------------------------- field layouts

namespace {

using detail::FieldSpec;
using detail::RecordContext;
using detail::od::value;

// The record's own token; remembered for later error messages of the same record.
template <class R>
void read_own_token(value& v, RecordContext& ctx, R& r, bool allow_short = false) {
  r.token = detail::read_token(v, ctx, allow_short);
  ctx.token = r.token;
  if (r.token.empty()) ctx.fail("a non-empty token");
}

#define NSG_FIELD(R, key, body)                           \
  FieldSpec<R> {                                          \
    key, [](value& v, RecordContext& ctx, R& r) { body; } \
  }
#define NSG_OPTIONAL_FIELD(R, key, body)                         \
  FieldSpec<R> {                                                 \
    key, [](value& v, RecordContext& ctx, R& r) { body; }, false \
  }
#define NSG_TOKEN(R, member) NSG_FIELD(R, #member, r.member = detail::read_token(v, ctx))

template <class R>
struct Layout;

template <>
struct Layout<Category> {
  static constexpr std::array kFields{
      NSG_FIELD(Category, "token", read_own_token(v, ctx, r)),
      NSG_FIELD(Category, "name", r.name = detail::read_string(v, ctx)),
      NSG_FIELD(Category, "description", r.description = detail::read_string(v, ctx)),
      NSG_OPTIONAL_FIELD(Category, "index", r.index = detail::read_int32(v, ctx)),
  };
};

template <>
struct Layout<Attribute> {
  static constexpr std::array kFields{
      NSG_FIELD(Attribute, "token", read_own_token(v, ctx, r)),
      NSG_FIELD(Attribute, "name", r.name = detail::read_string(v, ctx)),
      NSG_FIELD(Attribute, "description", r.description = detail::read_string(v, ctx)),
  };
};

template <>
struct Layout<Visibility> {
  static constexpr std::array kFields{
      NSG_FIELD(Visibility, "token", read_own_token(v, ctx, r, true)),
      NSG_FIELD(Visibility, "level", r.level = detail::read_string(v, ctx)),
      NSG_FIELD(Visibility, "description", r.description = detail::read_string(v, ctx)),
  };
};

Modality parse_modality(value& v, RecordContext& ctx) {
  const std::string_view s = detail::read_string(v, ctx);
  if (s == "camera") return Modality::kCamera;
  if (s == "lidar") return Modality::kLidar;
  if (s == "radar") return Modality::kRadar;
  ctx.fail("\"camera\", \"lidar\" or \"radar\", got \"" + std::string(s) + "\"");
}

template <>
struct Layout<Sensor> {
  static constexpr std::array kFields{
      NSG_FIELD(Sensor, "token", read_own_token(v, ctx, r)),
      NSG_FIELD(Sensor, "channel", r.channel = detail::read_string(v, ctx)),
      NSG_FIELD(Sensor, "modality", r.modality = parse_modality(v, ctx)),
  };
};

template <>
struct Layout<CalibratedSensor> {
  static constexpr std::array kFields{
      NSG_FIELD(CalibratedSensor, "token", read_own_token(v, ctx, r)),
      NSG_TOKEN(CalibratedSensor, sensor_token),
      NSG_FIELD(CalibratedSensor, "translation", r.translation = detail::read_numbers<3>(v, ctx)),
      NSG_FIELD(CalibratedSensor, "rotation", r.rotation = detail::read_quaternion(v, ctx)),
      NSG_FIELD(CalibratedSensor, "camera_intrinsic", r.camera_intrinsic = detail::read_matrix3_or_empty(v, ctx)),
  };
};

template <>
struct Layout<EgoPose> {
  static constexpr std::array kFields{
      NSG_FIELD(EgoPose, "token", read_own_token(v, ctx, r)),
      NSG_FIELD(EgoPose, "timestamp", r.timestamp_us = detail::read_int64(v, ctx)),
      NSG_FIELD(EgoPose, "rotation", r.rotation = detail::read_quaternion(v, ctx)),
      NSG_FIELD(EgoPose, "translation", r.translation = detail::read_numbers<3>(v, ctx)),
  };
};

template <>
struct Layout<Log> {
  static constexpr std::array kFields{
      NSG_FIELD(Log, "token", read_own_token(v, ctx, r)),
      NSG_FIELD(Log, "logfile", r.logfile = detail::read_string(v, ctx)),
      NSG_FIELD(Log, "vehicle", r.vehicle = detail::read_string(v, ctx)),
      NSG_FIELD(Log, "date_captured", r.date_captured = detail::read_string(v, ctx)),
      NSG_FIELD(Log, "location", r.location = detail::read_string(v, ctx)),
  };
};

template <>
struct Layout<Map> {
  static constexpr std::array kFields{
      NSG_FIELD(Map, "token", read_own_token(v, ctx, r)),
      NSG_FIELD(Map, "category", r.category = detail::read_string(v, ctx)),
      NSG_FIELD(Map, "filename", r.filename = detail::read_string(v, ctx)),
      NSG_FIELD(Map, "log_tokens", r.log_tokens = detail::read_token_list(v, ctx)),
  };
};

template <>
struct Layout<Scene> {
  static constexpr std::array kFields{
      NSG_FIELD(Scene, "token", read_own_token(v, ctx, r)),
      NSG_TOKEN(Scene, log_token),
      NSG_FIELD(Scene, "nbr_samples", r.nbr_samples = detail::read_int32(v, ctx)),
      NSG_TOKEN(Scene, first_sample_token),
      NSG_TOKEN(Scene, last_sample_token),
      NSG_FIELD(Scene, "name", r.name = detail::read_string(v, ctx)),
      NSG_FIELD(Scene, "description", r.description = detail::read_string(v, ctx)),
  };
};

template <>
struct Layout<Sample> {
  static constexpr std::array kFields{
      NSG_FIELD(Sample, "token", read_own_token(v, ctx, r)),
      NSG_FIELD(Sample, "timestamp", r.timestamp_us = detail::read_int64(v, ctx)),
      NSG_FIELD(Sample, "prev", r.prev_token = detail::read_token(v, ctx)),
      NSG_FIELD(Sample, "next", r.next_token = detail::read_token(v, ctx)),
      NSG_TOKEN(Sample, scene_token),
  };
};

template <>
struct Layout<SampleData> {
  static constexpr std::array kFields{
      NSG_FIELD(SampleData, "token", read_own_token(v, ctx, r)),
      NSG_TOKEN(SampleData, sample_token),
      NSG_TOKEN(SampleData, ego_pose_token),
      NSG_TOKEN(SampleData, calibrated_sensor_token),
      NSG_FIELD(SampleData, "timestamp", r.timestamp_us = detail::read_int64(v, ctx)),
      NSG_FIELD(SampleData, "fileformat", r.fileformat = detail::read_string(v, ctx)),
      NSG_FIELD(SampleData, "is_key_frame", r.is_key_frame = detail::read_bool(v, ctx)),
      NSG_FIELD(SampleData, "height", r.height = detail::read_int32(v, ctx)),
      NSG_FIELD(SampleData, "width", r.width = detail::read_int32(v, ctx)),
      NSG_FIELD(SampleData, "filename", r.filename = detail::read_string(v, ctx)),
      NSG_FIELD(SampleData, "prev", r.prev_token = detail::read_token(v, ctx)),
      NSG_FIELD(SampleData, "next", r.next_token = detail::read_token(v, ctx)),
  };
};

template <>
struct Layout<SampleAnnotation> {
  static constexpr std::array kFields{
      NSG_FIELD(SampleAnnotation, "token", read_own_token(v, ctx, r)),
      NSG_TOKEN(SampleAnnotation, sample_token),
      NSG_TOKEN(SampleAnnotation, instance_token),
      NSG_FIELD(SampleAnnotation, "visibility_token", r.visibility_token = detail::read_token(v, ctx, true)),
      NSG_FIELD(SampleAnnotation, "attribute_tokens", r.attribute_tokens = detail::read_token_list(v, ctx)),
      NSG_FIELD(SampleAnnotation, "translation", r.translation = detail::read_numbers<3>(v, ctx)),
      NSG_FIELD(SampleAnnotation, "size", r.size = detail::read_numbers<3>(v, ctx)),
      NSG_FIELD(SampleAnnotation, "rotation", r.rotation = detail::read_quaternion(v, ctx)),
      NSG_FIELD(SampleAnnotation, "prev", r.prev_token = detail::read_token(v, ctx)),
      NSG_FIELD(SampleAnnotation, "next", r.next_token = detail::read_token(v, ctx)),
      NSG_FIELD(SampleAnnotation, "num_lidar_pts", r.num_lidar_pts = detail::read_int32(v, ctx)),
      NSG_FIELD(SampleAnnotation, "num_radar_pts", r.num_radar_pts = detail::read_int32(v, ctx)),
  };
};

template <>
struct Layout<Instance> {
  static constexpr std::array kFields{
      NSG_FIELD(Instance, "token", read_own_token(v, ctx, r)),
      NSG_TOKEN(Instance, category_token),
      NSG_FIELD(Instance, "nbr_annotations", r.nbr_annotations = detail::read_int32(v, ctx)),
      NSG_TOKEN(Instance, first_annotation_token),
      NSG_TOKEN(Instance, last_annotation_token),
  };
};

#undef NSG_FIELD
#undef NSG_OPTIONAL_FIELD
#undef NSG_TOKEN

}  // namespace

template <class Record>
std::vector<Record> read_table(const std::filesystem::path& file) {
  return detail::read_records<Record>(file, [](detail::od::object& object, RecordContext& ctx, Record& r) {
    detail::read_record(object, ctx, Layout<Record>::kFields, r);
  });
}

template <class Record>
Table<Record> Table<Record>::load(const std::filesystem::path& file) {
  Table<Record> t;
  t.file_ = file.string();
  t.rows_ = read_table<Record>(file);
  if (t.rows_.size() > static_cast<size_t>(std::numeric_limits<Index>::max()))  // row indices are int32
    throw ParseError(t.file_, "", "at most 2147483647 records (the table's row indices are 32-bit)");
  const Index dup = t.index_.build(t.rows_.size(), [&](size_t i) -> const Token& { return t.rows_[i].token; });
  if (dup != kNoIndex) {
    const Token& token = t.rows_[static_cast<size_t>(dup)].token;
    const Index first = t.find(token);
    throw ParseError(t.file_, "record " + std::to_string(dup) + " (token " + token.str() + ")",
                     "a unique token (already used by record " + std::to_string(first) + ")");
  }
  return t;
}

template <class Record>
Index Table<Record>::find(const Token& token) const {
  return index_.find(token, [&](size_t i) -> const Token& { return rows_[i].token; });
}

template <class Record>
const Record& Table<Record>::get(const Token& token) const {
  const Index i = find(token);
  if (i == kNoIndex) throw DataError(file_, token.str(), std::string("unknown ") + table_name<Record>() + " token");
  return rows_[static_cast<size_t>(i)];
}

#define NSG_TABLE(Record, name)                                                  \
  template <>                                                                    \
  const char* table_name<Record>() {                                             \
    return name;                                                                 \
  }                                                                              \
  template std::vector<Record> read_table<Record>(const std::filesystem::path&); \
  template class Table<Record>;

NSG_TABLE(Category, "category")
NSG_TABLE(Attribute, "attribute")
NSG_TABLE(Visibility, "visibility")
NSG_TABLE(Sensor, "sensor")
NSG_TABLE(CalibratedSensor, "calibrated_sensor")
NSG_TABLE(EgoPose, "ego_pose")
NSG_TABLE(Log, "log")
NSG_TABLE(Map, "map")
NSG_TABLE(Scene, "scene")
NSG_TABLE(Sample, "sample")
NSG_TABLE(SampleData, "sample_data")
NSG_TABLE(SampleAnnotation, "sample_annotation")
NSG_TABLE(Instance, "instance")
#undef NSG_TABLE

}  // namespace nsg::nuscenes
