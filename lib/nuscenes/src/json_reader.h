#pragma once
// simdjson on-demand helpers shared by the table and detection readers (private header:
// simdjson stays out of the public API). Every failure throws ParseError naming the file,
// the record (index, and token once read) and the key with what was expected.
#include <simdjson.h>

#include <array>
#include <cstdint>
#include <algorithm>
#include <filesystem>
#include <future>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/nuscenes/tables.h"
#include "nsg/nuscenes/token.h"

namespace nsg::nuscenes::detail {

namespace od = simdjson::ondemand;

// Where the reader is: used only to build error messages.
struct RecordContext {
  std::string file;
  std::string record_prefix;  // e.g. "" or "results[<sample token>]"
  size_t index = 0;           // record number in its array
  Token token;                // the record's token once read (formatted only on error)
  // The record's text (error path: a failure before its "token" key was read still
  // names the token, found by scanning the object's top level).
  const char* record_begin = nullptr;
  const char* text_end = nullptr;
  std::string_view key;  // current key (points into a static field spec)

  std::string record() const;
  [[noreturn]] void fail(const std::string& expected, simdjson::error_code ec = simdjson::SUCCESS) const;
};

// Whole file into a simdjson padded buffer (one copy of the file in memory).
simdjson::padded_string load_padded(const std::filesystem::path& file);

double read_double(od::value& v, const RecordContext& ctx);
std::int64_t read_int64(od::value& v, const RecordContext& ctx);
std::int32_t read_int32(od::value& v, const RecordContext& ctx);
bool read_bool(od::value& v, const RecordContext& ctx);
std::string_view read_string(od::value& v, const RecordContext& ctx);
Token read_token(od::value& v, const RecordContext& ctx, bool allow_short = false);
std::vector<Token> read_token_list(od::value& v, const RecordContext& ctx);
// Fixed-arity number array ("translation": 3, "rotation": 4, "velocity": 2).
template <size_t N>
std::array<double, N> read_numbers(od::value& v, const RecordContext& ctx);
Quaternion read_quaternion(od::value& v, const RecordContext& ctx);
// `[]` → nullopt; else exactly 3 rows of 3 finite numbers.
std::optional<Matrix3> read_matrix3_or_empty(od::value& v, const RecordContext& ctx);

// Declarative record layout: one entry per key; `read` stores the value into the record.
template <class R>
struct FieldSpec {
  std::string_view key;
  void (*read)(od::value& v, RecordContext& ctx, R& r);
  bool required = true;
};

// Reads one object: keys in any order, unknown keys skipped, each known key at most once,
// every required key present.
template <class R, size_t N>
void read_record(od::object& object, RecordContext& ctx, const std::array<FieldSpec<R>, N>& spec, R& record) {
  static_assert(N <= 64);
  std::uint64_t seen = 0;
  size_t k = N - 1;
  for (auto field_result : object) {
    od::field field;
    ctx.key = {};
    if (auto ec = std::move(field_result).get(field)) ctx.fail("a key/value pair", ec);
    // Raw key bytes compared without unescaping (keys of these files carry no escapes);
    // the search starts after the last match, which is the next key in the usual order.
    const od::raw_json_string raw_key = field.key();
    size_t tries = 0;
    do {
      k = k + 1 == N ? 0 : k + 1;
    } while (!raw_key.unsafe_is_equal(spec[k].key) && ++tries < N);
    if (tries == N) continue;  // unknown keys (e.g. devkit-added fields) are skipped
    ctx.key = spec[k].key;
    if (seen & (std::uint64_t{1} << k)) ctx.fail("the key to appear once per record");
    seen |= std::uint64_t{1} << k;
    od::value value = field.value();
    spec[k].read(value, ctx, record);
  }
  for (size_t k = 0; k < N; ++k) {
    if (spec[k].required && !(seen & (std::uint64_t{1} << k))) {
      ctx.key = spec[k].key;
      ctx.fail("required key \"" + std::string(spec[k].key) + "\" (missing)");
    }
  }
  ctx.key = {};
}

// True once the whole document was consumed (no trailing content after the root value).
inline bool at_end(od::document& doc) { return doc.current_location().error() == simdjson::OUT_OF_BOUNDS; }

// Upper bound of the records in a JSON array of flat objects: the number of '{' (a fast
// vectorised count), so a table can reserve once instead of regrowing (peak memory).
size_t count_open_braces(std::string_view json);

// Number of leading records of a JSON array text that parse as a valid array on their own
// (error path only); `last_token` receives the token of the next, broken record if found.
size_t complete_records(const char* data, size_t length, Token& broken_token);

// Parses one JSON array text and calls on_record for each object; ctx.index continues
// from `first_index`. Returns the number of records.
template <class OnRecord>
size_t parse_array_text(od::parser& parser, const char* data, size_t length, size_t capacity, RecordContext& ctx,
                        size_t first_index, OnRecord& on_record) {
  ctx.index = first_index;
  ctx.token = Token();
  ctx.key = {};
  od::document doc;
  od::array array;
  simdjson::error_code ec = parser.iterate(data, length, capacity).get(doc);
  if (!ec) ec = doc.get_array().get(array);
  if (ec) {
    // simdjson rejects a broken document as a whole: locate the first record that does
    // not parse so the message can name it.
    ctx.index = first_index + complete_records(data, length, ctx.token);
    ctx.fail("a complete JSON array of records (the file is malformed or truncated in or after this record)", ec);
  }
  size_t index = first_index;
  for (auto element : array) {
    ctx.index = index;
    ctx.token = Token();
    ctx.key = {};
    const char* begin = nullptr;
    ctx.record_begin = element.current_location().get(begin) ? nullptr : begin;
    ctx.text_end = data + length;
    od::object object;
    if (auto ec = element.get_object().get(object)) ctx.fail("a JSON object", ec);
    on_record(object, ctx);
    ++index;
  }
  if (!at_end(doc)) {
    ctx.index = index;
    ctx.key = {};
    ctx.token = Token();
    ctx.fail("end of file after the top-level array");
  }
  return index - first_index;
}

// Splits a large top-level array of flat records into windows of about `chunk_bytes`,
// each handed out as a standalone array "[rec, …, rec]", so memory holds one window (and
// its simdjson index), not the whole file. A window ends after a '}' followed by ','; if
// that '}' was inside a string simdjson reports it, and the caller falls back to the
// whole-file parse (which then gives the exact error, or succeeds).
class ArrayChunker {
 public:
  ArrayChunker(const std::filesystem::path& file, size_t chunk_bytes);
  ~ArrayChunker();
  ArrayChunker(const ArrayChunker&) = delete;
  ArrayChunker& operator=(const ArrayChunker&) = delete;
  // The next window (data, length, allocated bytes incl. padding); false when done.
  // Two buffers alternate, so a window stays valid until the next-but-one call (two
  // windows can be parsed at once without copying them).
  bool next(const char*& data, size_t& length, size_t& capacity);

 private:
  void read_more(std::string& buffer);
  std::string file_;
  std::FILE* f_ = nullptr;
  size_t chunk_bytes_;
  std::string buffers_[2];  // [0] = '['; window bytes from 1 to length_
  int current_ = 0;
  size_t length_ = 1;
  size_t carry_from_ = 0;  // in the previous buffer: start of the bytes after the last cut (0: none)
  bool eof_ = false;
  bool started_ = false;
  bool done_ = false;
};

// Window size for big tables (NSG_JSON_CHUNK_BYTES overrides it, for tests); files up to
// twice this size are parsed whole.
size_t json_chunk_bytes();

// Reads a top-level JSON array of objects into records: fill(object, ctx, record) reads
// one. Files larger than two windows are read window by window (memory: one window, not
// the file) with two windows parsed concurrently (the helper thread fills a side vector
// that is appended in order). Any ParseError there re-runs the plain whole-file parse,
// which reports the exact record index (or succeeds if a window cut was misplaced).
template <class Record, class Fill>
std::vector<Record> read_records(const std::filesystem::path& file, Fill fill) {
  std::vector<Record> rows;
  const size_t chunk = json_chunk_bytes();
  std::error_code size_error;
  const auto file_size = std::filesystem::file_size(file, size_error);
  if (!size_error && file_size > 2 * chunk) {
    try {
      ArrayChunker chunker(file, chunk);
      od::parser parser_a, parser_b;
      RecordContext ctx_a, ctx_b;
      ctx_a.file = ctx_b.file = file.string();
      std::vector<Record> side;
      auto to_rows = [&](od::object& o, RecordContext& ctx) { fill(o, ctx, rows.emplace_back()); };
      auto to_side = [&](od::object& o, RecordContext& ctx) { fill(o, ctx, side.emplace_back()); };
      const char* data = nullptr;
      size_t length = 0, capacity = 0, index = 0;
      bool first = true;
      while (chunker.next(data, length, capacity)) {
        if (first) {  // records are alike: extrapolate the count from the first window
          rows.reserve(count_open_braces({data, length}) * (file_size / length + 1) * 103 / 100 + 16);
          first = false;
        }
        // Window A stays valid while the chunker fills its other buffer with window B,
        // which a helper thread parses while this thread parses A.
        const char* data_a = data;
        const size_t length_a = length, capacity_a = capacity;
        const char* data_b = nullptr;
        size_t length_b = 0, capacity_b = 0;
        const bool has_b = chunker.next(data_b, length_b, capacity_b);
        std::future<void> b;
        side.clear();
        if (has_b) {
          b = std::async(std::launch::async,
                         [&] { parse_array_text(parser_b, data_b, length_b, capacity_b, ctx_b, 0, to_side); });
        }
        index += parse_array_text(parser_a, data_a, length_a, capacity_a, ctx_a, index, to_rows);
        if (has_b) {
          b.get();
          index += side.size();
          std::move(side.begin(), side.end(), std::back_inserter(rows));
        }
      }
      return rows;
    } catch (const ParseError&) {
      // simdjson parses one document of at most 4 GiB (32-bit structural indices): a
      // larger file cannot be re-parsed whole, so the window's own error stands.
      if (file_size > simdjson::SIMDJSON_MAXSIZE_BYTES) throw;
      rows = {};  // fall through to the whole-file parse
    }
  }
  simdjson::padded_string json = load_padded(file);
  rows.reserve(count_open_braces(json));
  od::parser parser;
  RecordContext ctx;
  ctx.file = file.string();
  auto to_rows = [&](od::object& o, RecordContext& c) { fill(o, c, rows.emplace_back()); };
  parse_array_text(parser, json.data(), json.size(), json.size() + simdjson::SIMDJSON_PADDING, ctx, 0, to_rows);
  return rows;
}

}  // namespace nsg::nuscenes::detail
