#include "py_json.h"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "nsg/core/error.h"

namespace nsg::synth {

std::string python_float_repr(double value) {
  if (!std::isfinite(value)) throw InternalError("", "json", "non-finite float in output");
  if (value == 0.0) return std::signbit(value) ? "-0.0" : "0.0";
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::scientific);
  const std::string sci(buf, res.ptr);  // e.g. "-1.2345e-05"
  const size_t epos = sci.find('e');
  std::string mant = sci.substr(0, epos);
  const int exp = std::stoi(sci.substr(epos + 1));
  std::string sign;
  if (mant[0] == '-') {
    sign = "-";
    mant.erase(0, 1);
  }
  std::string digits;
  for (char c : mant)
    if (c != '.') digits += c;
  if (exp >= -4 && exp < 16) {
    std::string out;
    if (exp < 0) {
      out = "0." + std::string(static_cast<size_t>(-exp - 1), '0') + digits;
    } else if (static_cast<int>(digits.size()) <= exp + 1) {
      out = digits + std::string(static_cast<size_t>(exp + 1 - static_cast<int>(digits.size())), '0') + ".0";
    } else {
      out = digits.substr(0, static_cast<size_t>(exp + 1)) + "." + digits.substr(static_cast<size_t>(exp + 1));
    }
    return sign + out;
  }
  std::string m = digits.size() == 1 ? digits : digits.substr(0, 1) + "." + digits.substr(1);
  char e[16];
  std::snprintf(e, sizeof e, "e%c%02d", exp < 0 ? '-' : '+', std::abs(exp));
  return sign + m + e;
}

namespace {

void append_string(std::string& out, const std::string& s) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20 || c >= 0x7f) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", c);  // ASCII-only data in practice (ensure_ascii)
          out += b;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  out += '"';
}

}  // namespace

void append_py_json(std::string& out, const PyJson& v, PyJsonStyle style) {
  const bool ind = style == PyJsonStyle::kIndent0;
  const char* item_sep = ind ? ",\n" : ", ";
  switch (v.type()) {
    case PyJson::value_t::null: out += "null"; break;
    case PyJson::value_t::boolean: out += v.get<bool>() ? "true" : "false"; break;
    case PyJson::value_t::number_integer: out += std::to_string(v.get<int64_t>()); break;
    case PyJson::value_t::number_unsigned: out += std::to_string(v.get<uint64_t>()); break;
    case PyJson::value_t::number_float: out += python_float_repr(v.get<double>()); break;
    case PyJson::value_t::string: append_string(out, v.get_ref<const std::string&>()); break;
    case PyJson::value_t::array: {
      if (v.empty()) {
        out += "[]";
        break;
      }
      out += ind ? "[\n" : "[";
      bool first = true;
      for (const auto& item : v) {
        if (!first) out += item_sep;
        first = false;
        append_py_json(out, item, style);
      }
      out += ind ? "\n]" : "]";
      break;
    }
    case PyJson::value_t::object: {
      if (v.empty()) {
        out += "{}";
        break;
      }
      out += ind ? "{\n" : "{";
      bool first = true;
      for (auto it = v.begin(); it != v.end(); ++it) {
        if (!first) out += item_sep;
        first = false;
        append_string(out, it.key());
        out += ": ";
        append_py_json(out, it.value(), style);
      }
      out += ind ? "\n}" : "}";
      break;
    }
    default: throw InternalError("", "json", "unsupported JSON value type");
  }
}

std::string py_json_dump(const PyJson& value, PyJsonStyle style) {
  std::string out;
  append_py_json(out, value, style);
  return out;
}

}  // namespace nsg::synth
