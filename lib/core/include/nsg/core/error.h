#pragma once
// Error tree of the toolkit. Every message names where the problem is (file, and the
// record/token/line inside it) and what was expected, so a user can find and fix it.
#include <stdexcept>
#include <string>

namespace nsg {

// Process exit codes shared by every command (docs/architecture.md).
enum ExitCode : int { kExitOk = 0, kExitProblems = 1, kExitInput = 2, kExitInternal = 3 };

class Error : public std::runtime_error {
 public:
  // file: path of the offending input ("" if none); record: token, key or line inside it
  // ("" if none); expected: what was expected / what went wrong.
  Error(std::string file, std::string record, std::string expected);

  const std::string& file() const { return file_; }
  const std::string& record() const { return record_; }
  const std::string& expected() const { return expected_; }
  virtual int exit_code() const { return kExitInput; }

 private:
  std::string file_;
  std::string record_;
  std::string expected_;
};

// Malformed input: not JSON, wrong type, truncated binary.
class ParseError : public Error {
 public:
  using Error::Error;
};
// Well-formed input that is inconsistent: dangling token, NaN pose, wrong image size.
class DataError : public Error {
 public:
  using Error::Error;
};
// The file system: missing file, unreadable, disk full.
class IoError : public Error {
 public:
  using Error::Error;
};
// Bad options or config values.
class ConfigError : public Error {
 public:
  using Error::Error;
};
// A broken invariant of our own code (exit 3), never bad input.
class InternalError : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitInternal; }
};

// Formats "file: record: expected" leaving out empty parts.
std::string format_error_message(const std::string& file, const std::string& record, const std::string& expected);

}  // namespace nsg

// Throws ErrorType(file, record, message) when cond is false. For data checks in lib/
// (never assert(), which vanishes in release builds).
#define NSG_CHECK(cond, ErrorType, file, record, message)      \
  do {                                                         \
    if (!(cond)) throw ErrorType((file), (record), (message)); \
  } while (0)
