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
    if (part != &expected) {
      out += printable_text(*part);
      continue;
    }
    // What was expected may run over several lines (a list of problems, what would lower
    // an estimate): its line breaks stay, each continuation indented, so no line of it can
    // pass for a line of its own in a log.
    const std::string text = printable_text(*part, /*keep_newlines=*/true);
    for (size_t i = 0; i < text.size(); ++i) {
      out += text[i];
      if (text[i] == '\n' && text.compare(i + 1, 2, "  ") != 0) out += "  ";
    }
  }
  return out;
}

Error::Error(std::string file, std::string record, std::string expected)
    : std::runtime_error(format_error_message(file, record, expected)),
      file_(std::move(file)),
      record_(std::move(record)),
      expected_(std::move(expected)) {}

}  // namespace nsg
