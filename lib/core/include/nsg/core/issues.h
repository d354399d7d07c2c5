#pragma once
// Recoverable problems (map defects, validation findings) collected into a list instead of
// thrown; `--strict` turns errors among them into exceptions (see Issues::throw_if_strict).
#include <string>
#include <vector>

namespace nsg {

enum class Severity { kInfo, kWarning, kError };
const char* severity_name(Severity s);

struct Issue {
  Severity severity = Severity::kError;
  std::string check;    // dotted check name, e.g. "graph.edge_length"
  std::string subject;  // file / shard / key / token the issue is about
  std::string message;  // what was found and what was expected
};

class Issues {
 public:
  void add(Severity severity, std::string check, std::string subject, std::string message);
  void error(std::string check, std::string subject, std::string message) {
    add(Severity::kError, std::move(check), std::move(subject), std::move(message));
  }
  void warning(std::string check, std::string subject, std::string message) {
    add(Severity::kWarning, std::move(check), std::move(subject), std::move(message));
  }
  void append(const Issues& other);

  const std::vector<Issue>& items() const { return items_; }
  size_t size() const { return items_.size(); }
  bool empty() const { return items_.empty(); }
  size_t count(Severity s) const;
  // Number of issues whose check name equals `check`.
  size_t count_check(const std::string& check) const;

  // One line per issue: "<severity> <check> <subject>: <message>".
  std::string format() const;
  // Throws DataError naming the first error-severity issue (used by --strict).
  void throw_if_errors(const std::string& file) const;

 private:
  std::vector<Issue> items_;
};

}  // namespace nsg
