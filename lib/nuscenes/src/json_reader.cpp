#include "json_reader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace nsg::nuscenes::detail {

namespace {

std::string_view trim_view(std::string_view s) {
  while (!s.empty() &&
         (s.back() == ' ' || s.back() == '\n' || s.back() == '\r' || s.back() == '\t' || s.back() == ',')) {
    s.remove_suffix(1);
  }
  return s;
}

const char* describe(simdjson::error_code ec) {
  switch (ec) {
    case simdjson::INCOMPLETE_ARRAY_OR_OBJECT:
    case simdjson::TAPE_ERROR:
    case simdjson::UNCLOSED_STRING:
    case simdjson::EMPTY:
    case simdjson::DEPTH_ERROR: return "truncated or malformed JSON";
    case simdjson::INCORRECT_TYPE: return "wrong type";
    case simdjson::NUMBER_ERROR:
    case simdjson::NUMBER_OUT_OF_RANGE: return "not a representable number (NaN/Infinity are not JSON)";
    case simdjson::T_ATOM_ERROR:
    case simdjson::F_ATOM_ERROR:
    case simdjson::N_ATOM_ERROR: return "invalid literal (NaN/Infinity are not JSON)";
    default: return "malformed JSON";
  }
}

// What the file holds where a value was expected, for messages ("got NaN").
std::string got(od::value& v) {
  const std::string_view raw = trim_view(v.raw_json_token());
  if (raw.size() > 40) return ", got " + std::string(raw.substr(0, 40)) + "…";
  return ", got " + std::string(raw);
}

}  // namespace

namespace {

// The value of the top-level "token" key of the JSON object starting at `begin` (error
// path only: a record that fails before its token was read). Skips strings (with
// escapes) and nested values; an empty token if there is none or the text is broken.
Token token_in_object(const char* begin, const char* end) {
  if (begin == nullptr || begin >= end || *begin != '{') return {};
  int depth = 0;
  bool expect_token_value = false;
  for (const char* p = begin; p < end; ++p) {
    const char c = *p;
    if (c == '{' || c == '[') {
      ++depth;
    } else if (c == '}' || c == ']') {
      if (--depth == 0) return {};
    } else if (c == '"') {
      const char* q = p + 1;
      while (q < end && *q != '"') q += (*q == '\\') ? 2 : 1;
      if (q >= end) return {};
      const std::string_view str(p + 1, static_cast<size_t>(q - p - 1));
      if (depth == 1 && expect_token_value) return Token::parse(str).value_or(Token());
      if (depth == 1) {  // a key if a colon follows
        const char* r = q + 1;
        while (r < end && std::isspace(static_cast<unsigned char>(*r))) ++r;
        expect_token_value = r < end && *r == ':' && str == "token";
      }
      p = q;
    } else if (depth == 1 && c == ',') {
      expect_token_value = false;
    }
  }
  return {};
}

}  // namespace

std::string RecordContext::record() const {
  std::string r = record_prefix;
  if (!r.empty()) r += " ";
  r += "record " + std::to_string(index);
  const Token named = token.empty() ? token_in_object(record_begin, text_end) : token;
  if (!named.empty()) r += " (token " + named.str() + ")";
  if (!key.empty()) r += " key \"" + std::string(key) + "\"";
  return r;
}

void RecordContext::fail(const std::string& expected, simdjson::error_code ec) const {
  std::string message = "expected " + expected;
  if (ec != simdjson::SUCCESS) {
    message += std::string(" (") + describe(ec) + ": " + simdjson::error_message(ec) + ")";
  }
  throw ParseError(file, record(), message);
}

simdjson::padded_string load_padded(const std::filesystem::path& file) {
  simdjson::padded_string json;
  if (auto ec = simdjson::padded_string::load(file.string()).get(json)) {
    throw IoError(file.string(), "", std::string("cannot read file: ") + simdjson::error_message(ec));
  }
  return json;
}

size_t json_chunk_bytes() {
  const char* v = std::getenv("NSG_JSON_CHUNK_BYTES");
  const long long n = v != nullptr ? std::atoll(v) : 0;
  return n > 0 ? static_cast<size_t>(n) : size_t{1} << 20;  // 1 MB: stays in cache between simdjson's stages
}

ArrayChunker::ArrayChunker(const std::filesystem::path& file, size_t chunk_bytes)
    : file_(file.string()), chunk_bytes_(std::max<size_t>(chunk_bytes, 256)) {
  f_ = std::fopen(file_.c_str(), "rb");
  if (f_ == nullptr) throw IoError(file_, "", std::string("cannot open: ") + std::strerror(errno));
  buffers_[0].assign(1, '[');
  buffers_[1].assign(1, '[');
}

ArrayChunker::~ArrayChunker() {
  if (f_ != nullptr) std::fclose(f_);
}

void ArrayChunker::read_more(std::string& buffer) {
  if (buffer.size() < length_ + chunk_bytes_ + simdjson::SIMDJSON_PADDING) {
    buffer.resize(length_ + chunk_bytes_ + simdjson::SIMDJSON_PADDING);
  }
  const size_t n = std::fread(buffer.data() + length_, 1, chunk_bytes_, f_);
  if (std::ferror(f_)) throw IoError(file_, "", "read error");
  length_ += n;
  if (n < chunk_bytes_) eof_ = true;
}

bool ArrayChunker::next(const char*& data, size_t& length, size_t& capacity) {
  if (done_) return false;
  std::string& buffer = buffers_[current_];
  if (carry_from_ != 0) {  // the bytes after the last cut start this window
    const std::string& previous = buffers_[1 - current_];
    const size_t carry = length_ - carry_from_;
    if (buffer.size() < 1 + carry + chunk_bytes_ + simdjson::SIMDJSON_PADDING) {
      buffer.resize(1 + carry + chunk_bytes_ + simdjson::SIMDJSON_PADDING);
    }
    std::memcpy(buffer.data() + 1, previous.data() + carry_from_, carry);
    length_ = 1 + carry;
    carry_from_ = 0;
  }
  for (;;) {
    if (!eof_) read_more(buffer);
    if (!started_) {  // drop the file's own '[' (the buffer starts with one)
      size_t i = 1;
      while (i < length_ && std::isspace(static_cast<unsigned char>(buffer[i]))) ++i;
      if (i == length_ || buffer[i] != '[') throw ParseError(file_, "", "a JSON array of records");
      std::memmove(buffer.data() + 1, buffer.data() + i + 1, length_ - i - 1);
      length_ -= i;
      started_ = true;
    }
    if (eof_) {  // the rest, with the file's closing ']'
      std::memset(buffer.data() + length_, ' ', buffer.size() - length_);
      data = buffer.data();
      length = length_;
      capacity = buffer.size();
      done_ = true;
      return true;
    }
    // Last "}" + whitespace + "," in the window: a record boundary unless inside a string.
    for (size_t c = length_; c-- > 1;) {
      if (buffer[c] != '}') continue;
      size_t k = c + 1;
      while (k < length_ && std::isspace(static_cast<unsigned char>(buffer[k]))) ++k;
      if (k >= length_ || buffer[k] != ',') continue;
      buffer[c + 1] = ']';  // ≤ k: whitespace or the comma, not part of the next window
      data = buffer.data();
      length = c + 2;
      capacity = buffer.size();
      carry_from_ = k + 1;
      current_ = 1 - current_;
      return true;
    }
    // No boundary yet (a record longer than the window): read more into this buffer.
  }
}

size_t complete_records(const char* data, size_t length, Token& broken_token) {
  const std::string_view text(data, length);
  // Try successively shorter prefixes ending at a "}" + "," boundary until one parses.
  size_t end = text.size();
  for (int attempt = 0; attempt < 64; ++attempt) {
    const size_t c = text.rfind('}', end == 0 ? 0 : end - 1);
    if (c == std::string_view::npos || c == 0) break;
    end = c;
    size_t k = c + 1;
    while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
    if (k >= text.size() || text[k] != ',') continue;
    const size_t open = text.find('[');
    if (open == std::string_view::npos || open > c) break;
    simdjson::padded_string prefix(std::string(text.substr(open, c + 1 - open)) + "]");
    simdjson::ondemand::parser parser;
    simdjson::ondemand::document doc;
    simdjson::ondemand::array array;
    if (parser.iterate(prefix).get(doc) || doc.get_array().get(array)) continue;
    size_t n = 0;
    bool ok = true;
    for (auto element : array) {
      simdjson::ondemand::object object;
      if (element.get_object().get(object)) {
        ok = false;
        break;
      }
      for (auto field : object) {  // walk every value so errors surface
        if (field.error()) {
          ok = false;
          break;
        }
      }
      if (!ok) break;
      ++n;
    }
    if (!ok) continue;
    // The broken record starts after the comma; take its token if it is readable.
    const size_t key = text.find("\"token\"", k);
    if (key != std::string_view::npos) {
      const size_t q1 = text.find('"', text.find(':', key) + 1);
      const size_t q2 = q1 == std::string_view::npos ? q1 : text.find('"', q1 + 1);
      if (q2 != std::string_view::npos && q2 - q1 == 33) {
        if (auto t = Token::parse(text.substr(q1 + 1, 32))) broken_token = *t;
      }
    }
    return n;
  }
  return 0;
}

size_t count_open_braces(std::string_view json) {
  size_t n = 0;
  for (char c : json) n += (c == '{');
  return n;
}

double read_double(od::value& v, const RecordContext& ctx) {
  double d = 0.0;
  if (auto ec = v.get_double().get(d)) ctx.fail("a finite number" + got(v), ec);
  if (!std::isfinite(d)) ctx.fail("a finite number");
  return d;
}

std::int64_t read_int64(od::value& v, const RecordContext& ctx) {
  std::int64_t i = 0;
  if (auto ec = v.get_int64().get(i)) ctx.fail("an integer" + got(v), ec);
  return i;
}

std::int32_t read_int32(od::value& v, const RecordContext& ctx) {
  const std::int64_t i = read_int64(v, ctx);
  if (i < std::numeric_limits<std::int32_t>::min() || i > std::numeric_limits<std::int32_t>::max()) {
    ctx.fail("a 32-bit integer");
  }
  return static_cast<std::int32_t>(i);
}

bool read_bool(od::value& v, const RecordContext& ctx) {
  bool b = false;
  if (auto ec = v.get_bool().get(b)) ctx.fail("true or false" + got(v), ec);
  return b;
}

std::string_view read_string(od::value& v, const RecordContext& ctx) {
  // Fast path: a string without escapes is used in place (no unescaping copy).
  const std::string_view raw = v.raw_json_token();
  if (raw.size() >= 2 && raw.front() == '"') {
    size_t end = raw.size() - 1;
    while (end > 0 && raw[end] != '"') --end;  // skip whitespace after the closing quote
    if (end > 0) {
      const std::string_view content = raw.substr(1, end - 1);
      if (content.find('\\') == std::string_view::npos) return content;
    }
  }
  std::string_view s;
  if (auto ec = v.get_string().get(s)) ctx.fail("a string" + got(v), ec);
  return s;
}

Token read_token(od::value& v, const RecordContext& ctx, bool allow_short) {
  // Fast path: the 32 characters between the quotes, parsed in place (no scan for the
  // closing quote or escapes: a backslash is not a hex digit, so an escaped text fails
  // Token::parse and takes the path below, which accepts exactly the same tokens).
  const std::string_view raw = v.raw_json_token();
  if (raw.size() >= 34 && raw[0] == '"' && raw[33] == '"') {
    if (const std::optional<Token> t = Token::parse(raw.substr(1, 32))) return *t;
  }
  const std::string_view s = read_string(v, ctx);
  const std::optional<Token> t = Token::parse(s, allow_short);
  if (!t) {
    ctx.fail(std::string(allow_short ? "a token (32 lowercase hex chars or a short id)"
                                     : "a token of 32 lowercase hex chars or \"\"") +
             ", got \"" + std::string(s.substr(0, 64)) + "\"");
  }
  return *t;
}

std::vector<Token> read_token_list(od::value& v, const RecordContext& ctx) {
  od::array array;
  if (auto ec = v.get_array().get(array)) ctx.fail("an array of tokens", ec);
  std::vector<Token> out;
  for (auto element : array) {
    if (auto ec = element.error()) ctx.fail("an array of tokens", ec);
    od::value item = element.value_unsafe();
    out.push_back(read_token(item, ctx));
  }
  return out;
}

template <size_t N>
std::array<double, N> read_numbers(od::value& v, const RecordContext& ctx) {
  static const std::string what = "an array of " + std::to_string(N) + " finite numbers";  // built once
  od::array array;
  if (auto ec = v.get_array().get(array)) ctx.fail(what, ec);
  std::array<double, N> out{};
  size_t n = 0;
  for (auto element : array) {
    if (auto ec = element.error()) ctx.fail(what, ec);
    od::value item = element.value_unsafe();
    if (n == N) ctx.fail(what + " (got more)");
    double d = 0.0;
    if (auto ec = item.get_double().get(d)) ctx.fail(what + got(item), ec);
    if (!std::isfinite(d)) ctx.fail(what);
    out[n++] = d;
  }
  if (n != N) ctx.fail(what + " (got " + std::to_string(n) + ")");
  return out;
}

template std::array<double, 2> read_numbers<2>(od::value&, const RecordContext&);
template std::array<double, 3> read_numbers<3>(od::value&, const RecordContext&);
template std::array<double, 4> read_numbers<4>(od::value&, const RecordContext&);

Quaternion read_quaternion(od::value& v, const RecordContext& ctx) {
  const std::array<double, 4> q = read_numbers<4>(v, ctx);
  if (q[0] == 0.0 && q[1] == 0.0 && q[2] == 0.0 && q[3] == 0.0) ctx.fail("a non-zero quaternion [w, x, y, z]");
  return Quaternion::from_wxyz(q);
}

std::optional<Matrix3> read_matrix3_or_empty(od::value& v, const RecordContext& ctx) {
  const char* what = "[] or a 3x3 nested array of finite numbers";
  od::array rows;
  if (auto ec = v.get_array().get(rows)) ctx.fail(what, ec);
  Matrix3 m{};
  size_t n = 0;
  for (auto element : rows) {
    if (auto ec = element.error()) ctx.fail(what, ec);
    od::value row = element.value_unsafe();
    if (n == 3) ctx.fail(what);
    m[n++] = read_numbers<3>(row, ctx);
  }
  if (n == 0) return std::nullopt;
  if (n != 3) ctx.fail(what);
  return m;
}

}  // namespace nsg::nuscenes::detail
