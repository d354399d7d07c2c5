#include "nsg/core/issues.h"

#include "nsg/core/error.h"
#include "nsg/core/strings.h"

namespace nsg {

const char* severity_name(Severity s) {
  switch (s) {
    case Severity::kInfo: return "info";
    case Severity::kWarning: return "warning";
    case Severity::kError: return "error";
  }
  return "error";
}

namespace {
std::string more_message(const std::string& check, size_t more, size_t listed) {
  return "and " + std::to_string(more) + " more " + check + " issue(s) not listed (the first " +
         std::to_string(listed) + " are)";
}
}  // namespace

void Issues::add(Severity severity, std::string check, std::string subject, std::string message) {
  if (limit_per_check_ == 0) {
    items_.push_back({severity, std::move(check), std::move(subject), std::move(message)});
    return;
  }
  Overflow& o = per_check_[check];
  if (o.listed < limit_per_check_) {
    ++o.listed;
    items_.push_back({severity, std::move(check), std::move(subject), std::move(message)});
    return;
  }
  if (o.more++ == 0) {
    o.summary = items_.size();
    items_.push_back({severity, check, std::move(subject), ""});
  }
  items_[o.summary].message = more_message(check, o.more, limit_per_check_);
}

void Issues::append(const Issues& other) {
  if (limit_per_check_ == 0) {
    items_.insert(items_.end(), other.items_.begin(), other.items_.end());
    return;
  }
  for (size_t k = 0; k < other.items_.size(); ++k) {
    const Issue& i = other.items_[k];
    const auto theirs = other.per_check_.find(i.check);
    if (theirs == other.per_check_.end() || theirs->second.more == 0 || theirs->second.summary != k) {
      add(i.severity, i.check, i.subject, i.message);
      continue;
    }
    // Other's "… and K more": K more here too.
    Overflow& o = per_check_[i.check];
    if (o.more == 0) {
      o.summary = items_.size();
      items_.push_back({i.severity, i.check, i.subject, ""});
    }
    o.more += theirs->second.more;
    items_[o.summary].message = more_message(i.check, o.more, limit_per_check_);
  }
}

size_t Issues::count(Severity s) const {
  size_t n = 0;
  for (const Issue& i : items_) n += (i.severity == s);
  return n;
}

size_t Issues::count_check(const std::string& check) const {
  size_t n = 0;
  for (const Issue& i : items_) n += (i.check == check);
  return n;
}

std::string Issues::format() const {
  std::string out;
  for (const Issue& i : items_) {
    out += severity_name(i.severity);
    out += ' ';
    out += i.check;
    out += ' ';
    out += printable_text(i.subject);  // keys and paths from the input
    out += ": ";
    out += printable_text(i.message);
    out += '\n';
  }
  return out;
}

void Issues::throw_if_errors(const std::string& file) const {
  for (const Issue& i : items_) {
    if (i.severity == Severity::kError) {
      throw DataError(file, i.subject, i.check + ": " + i.message + " (strict mode)");
    }
  }
}

}  // namespace nsg
