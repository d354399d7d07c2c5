#include "nsg/core/error.h"

#include "nsg/core/strings.h"

namespace nsg {

std::string format_error_message(const std::string& file, const std::string& record, const std::string& expected) {
  std::string out;
  for (const std::string* part : {&file, &record, &expected}) {
    if (part->empty()) continue;
    if (!out.empty()) out += ": ";
    // File names, keys and quoted values come from outside: no control character of
    // theirs reaches a terminal or a log (the fields themselves keep the raw bytes).
    out += printable_text(*part);
  }
  return out;
}

Error::Error(std::string file, std::string record, std::string expected)
    : std::runtime_error(format_error_message(file, record, expected)),
      file_(std::move(file)),
      record_(std::move(record)),
      expected_(std::move(expected)) {}

}  // namespace nsg
