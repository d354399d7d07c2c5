#pragma once
// Recoverable problems (map defects, validation findings) collected into a list instead of
// thrown; `--strict` turns errors among them into exceptions (see Issues::throw_if_strict).
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace nsg {

// Issues listed per check where input can bring millions of them (submissions, schemas).
inline constexpr size_t kMaxListedIssues = 100;

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
  // Appends other's issues (through add, so this list's cap applies to them too).
  void append(const Issues& other);

  // Keeps at most `n` issues of each check; the rest are counted into one closing issue
  // per check ("… and K more"), so a hostile input with millions of problems costs a
  // bounded report. 0 = no cap (the default).
  void limit_per_check(size_t n) { limit_per_check_ = n; }
  // Whether an issue of `check` added now would be listed (false: only counted), so a
  // caller can skip composing its message.
  bool lists(const std::string& check) const {
    if (limit_per_check_ == 0) return true;
    const auto it = per_check_.find(check);
    return it == per_check_.end() || it->second.listed < limit_per_check_;
  }

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
  struct Overflow {
    size_t listed = 0;   // issues of the check kept
    size_t more = 0;     // issues of the check beyond the cap
    size_t summary = 0;  // index in items_ of the "… and K more" issue
  };
  std::vector<Issue> items_;
  size_t limit_per_check_ = 0;
  std::map<std::string, Overflow> per_check_;
};

}  // namespace nsg
