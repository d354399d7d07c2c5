#pragma once
// Table tokens (docs/nuscenes-input.md): 32 lowercase hex chars, stored as 16 bytes; the
// visibility table uses short tokens "1".."4"; "" is an empty link. Tokens are resolved
// to int32 row indices once at load (kNoIndex for empty links).
#include <array>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace nsg::nuscenes {

using Index = std::int32_t;
inline constexpr Index kNoIndex = -1;

class Token {
 public:
  enum class Kind : std::uint8_t { kEmpty = 0, kHex32 = 1, kShort = 2 };
  static constexpr size_t kMaxShortLength = 16;

  Token() = default;
  // Parses `text`: "" → empty, 32 lowercase hex chars → hex token, and when `allow_short`
  // 1..16 printable ASCII chars (visibility "1".."4"). std::nullopt if not a valid token.
  static std::optional<Token> parse(std::string_view text, bool allow_short = false);
  // Like parse() but throws std::invalid_argument; for tests and literals.
  static Token from_string(std::string_view text);

  bool empty() const { return kind_ == Kind::kEmpty; }
  Kind kind() const { return kind_; }
  std::string str() const;
  // Well-mixed for hex tokens (they are random); short tokens mix their bytes.
  std::uint64_t hash() const;

  friend bool operator==(const Token& a, const Token& b) {
    return a.kind_ == b.kind_ && a.length_ == b.length_ && std::memcmp(a.bytes_.data(), b.bytes_.data(), 16) == 0;
  }
  friend bool operator!=(const Token& a, const Token& b) { return !(a == b); }
  friend bool operator<(const Token& a, const Token& b);

 private:
  std::array<std::uint8_t, 16> bytes_{};
  Kind kind_ = Kind::kEmpty;
  std::uint8_t length_ = 0;  // characters of a short token
};

// Open-addressing token → row index map over a table's rows (4 bytes per slot, slots
// hold row indices; the tokens themselves stay in the rows). Build once, then lookup.
class TokenIndex {
 public:
  // token_at(i) returns the token of row i. Returns the index of the first duplicated row
  // (kNoIndex if all tokens are unique); empty tokens are not indexed.
  template <class TokenAt>
  Index build(size_t rows, TokenAt&& token_at);
  template <class TokenAt>
  Index find(const Token& token, TokenAt&& token_at) const;

 private:
  std::vector<Index> slots_;
  std::uint64_t mask_ = 0;
};

template <class TokenAt>
Index TokenIndex::build(size_t rows, TokenAt&& token_at) {
  size_t capacity = 16;
  while (capacity < rows * 2) capacity *= 2;
  slots_.assign(capacity, kNoIndex);
  mask_ = capacity - 1;
  for (size_t i = 0; i < rows; ++i) {
    const Token& t = token_at(i);
    if (t.empty()) continue;
    for (std::uint64_t s = t.hash() & mask_;; s = (s + 1) & mask_) {
      if (slots_[s] == kNoIndex) {
        slots_[s] = static_cast<Index>(i);
        break;
      }
      if (token_at(static_cast<size_t>(slots_[s])) == t) return static_cast<Index>(i);
    }
  }
  return kNoIndex;
}

template <class TokenAt>
Index TokenIndex::find(const Token& token, TokenAt&& token_at) const {
  if (token.empty() || slots_.empty()) return kNoIndex;
  for (std::uint64_t s = token.hash() & mask_;; s = (s + 1) & mask_) {
    const Index i = slots_[s];
    if (i == kNoIndex) return kNoIndex;
    if (token_at(static_cast<size_t>(i)) == token) return i;
  }
}

}  // namespace nsg::nuscenes
