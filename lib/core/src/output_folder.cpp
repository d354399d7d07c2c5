#include "nsg/core/output_folder.h"

#include <algorithm>
#include <system_error>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/strings.h"

namespace nsg {

namespace fs = std::filesystem;

namespace {

// How many unlisted files a refusal names before it gives only their count.
constexpr size_t kNamedInRefusal = 5;

fs::path resolved(const fs::path& p) {
  std::error_code ec;
  const fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
  return ec ? fs::absolute(p).lexically_normal() : r;
}

bool is_link(const fs::path& p) {
  std::error_code ec;
  return fs::is_symlink(fs::symlink_status(p, ec));
}

}  // namespace

const std::string& safe_name(const std::string& name, const std::string& file, const std::string& record) {
  const auto refuse = [&](const std::string& why) {
    throw DataError(file, record,
                    "a name usable as one file name (" + why +
                        "): not empty, not '.' or '..', no '/', '\\' or control characters, at most " +
                        std::to_string(kMaxNameBytes) + " bytes");
  };
  if (name.empty()) refuse("it is empty");
  if (name == "." || name == "..") refuse("it is '" + name + "'");
  if (name.size() > kMaxNameBytes) refuse(std::to_string(name.size()) + " bytes");
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '/' || c == '\\') refuse("'" + printable_text(name) + "' holds a path separator");
    if (u < 0x20 || u == 0x7f) refuse("'" + printable_text(name) + "' holds a control character");
  }
  return name;
}

bool same_folder(const fs::path& a, const fs::path& b) { return resolved(a) == resolved(b); }

bool inside_folder(const fs::path& inner, const fs::path& outer) {
  const fs::path in = resolved(inner), out = resolved(outer);
  const fs::path rel = in.lexically_relative(out);
  return !rel.empty() && *rel.begin() != "..";
}

void refuse_out_over_input(const fs::path& out, const fs::path& input, const std::string& input_option,
                           const std::string& out_option) {
  if (out.empty() || input.empty()) return;
  NSG_CHECK(!same_folder(out, input), ConfigError, out.string(), out_option,
            "a folder other than " + input_option + " (" + input.string() +
                "): the command would write over what it reads; choose another " + out_option);
  NSG_CHECK(!inside_folder(input, out), ConfigError, out.string(), out_option,
            "a folder that does not hold " + input_option + " (" + input.string() +
                "): replacing the output would remove it; choose another " + out_option);
}

bool is_temp_name(const std::string& file_name) {
  const size_t at = file_name.rfind(".tmp-");
  if (at == std::string::npos || at == 0) return false;
  const std::string tail = file_name.substr(at + 5);
  const size_t dash = tail.find('-');
  const auto digits = [](const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  return dash != std::string::npos && digits(tail.substr(0, dash)) && digits(tail.substr(dash + 1));
}

OutputFolder::OutputFolder(fs::path root, std::string option) : root_(std::move(root)), option_(std::move(option)) {
  NSG_CHECK(!root_.empty(), ConfigError, "", option_, "an output folder");
}

fs::path OutputFolder::path(const std::string& relative) const {
  NSG_CHECK(stays_inside(relative), ConfigError, root_.string(), option_,
            "a path inside the output folder, got '" + printable_text(relative) + "'");
  fs::path at = root_;
  const fs::path rel(relative);
  for (auto part = rel.begin(); part != rel.end(); ++part) {
    if (part->empty() || *part == ".") continue;
    at /= *part;
    std::error_code ec;
    const fs::file_status s = fs::symlink_status(at, ec);
    if (ec || !fs::exists(s)) break;  // nothing there yet: the rest is ours to create
    NSG_CHECK(
        !fs::is_symlink(s), DataError, at.string(), option_,
        "no symbolic link inside the output folder (it would lead the write out of " + root_.string() + "); remove it");
    NSG_CHECK(std::next(part) == rel.end() || fs::is_directory(s), DataError, at.string(), option_,
              "a folder (it is a file)");
  }
  return root_ / rel;
}

fs::path OutputFolder::prepare(const std::string& relative) const {
  const fs::path target = path(relative);
  std::error_code ec;
  if (!fs::is_symlink(fs::symlink_status(root_, ec))) fs::create_directories(root_, ec);
  fs::path at = root_;
  const fs::path parent = fs::path(relative).parent_path();
  for (const fs::path& part : parent) {
    if (part.empty() || part == ".") continue;
    at /= part;
    fs::create_directory(at, ec);  // path() has refused links and files on the way
    NSG_CHECK(!ec, IoError, at.string(), option_, "a folder that can be created (" + ec.message() + ")");
  }
  return target;
}

void OutputFolder::write(const std::string& relative, std::string_view bytes, Durability durability) const {
  write_file_atomic(prepare(relative), bytes, durability);
}

std::vector<std::string> OutputFolder::files_under(const std::vector<std::string>& owned) const {
  std::vector<std::string> files;
  for (const std::string& folder : owned) {
    const bool whole = folder == ".";  // the folder itself, which may be a link the user made
    const fs::path top = whole ? root_ : path(folder);
    std::error_code ec;
    const fs::file_status s = whole ? fs::status(top, ec) : fs::symlink_status(top, ec);
    if (ec || !fs::exists(s)) continue;
    if (!fs::is_directory(s)) {  // a file where a folder of ours belongs: not ours
      files.push_back(folder);
      continue;
    }
    // The default options do not follow links to folders: a link is listed, not entered.
    for (auto it = fs::recursive_directory_iterator(top, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
      if (it->is_directory() && !it->is_symlink()) continue;
      files.push_back(it->path().lexically_relative(root_).generic_string());
    }
    NSG_CHECK(!ec, IoError, top.string(), option_, "a readable folder (" + ec.message() + ")");
  }
  std::sort(files.begin(), files.end());
  return files;
}

void OutputFolder::refuse_unlisted(const std::set<std::string>& listed, const std::vector<std::string>& owned,
                                   const std::string& document) const {
  std::vector<std::string> foreign;
  for (const std::string& f : files_under(owned))
    if (!listed.count(f) && !is_temp_name(fs::path(f).filename().string())) foreign.push_back(printable_text(f));
  if (foreign.empty()) return;
  const size_t count = foreign.size();
  foreign.resize(std::min(count, kNamedInRefusal));
  throw ConfigError(
      root_.string(), option_,
      "a folder whose files " + document + " lists (nsgraph removes only files it wrote): " + std::to_string(count) +
          " other file(s) there, e.g. " + join(foreign, ", ") + "; move them away or choose another " + option_);
}

int64_t OutputFolder::remove_listed(const std::set<std::string>& listed, const std::vector<std::string>& owned,
                                    const std::string& document) const {
  refuse_unlisted(listed, owned, document);
  const std::vector<std::string> found = files_under(owned);
  int64_t removed = 0;
  for (const std::string& f : found) {
    const fs::path p = root_ / f;
    std::error_code ec;
    if (is_link(p) || !fs::is_regular_file(fs::symlink_status(p, ec))) continue;
    if (fs::remove(p, ec)) ++removed;
    NSG_CHECK(!ec, IoError, p.string(), option_, "a file that can be removed (" + ec.message() + ")");
  }
  // Folders left empty, deepest first (found is sorted, so reverse order visits children first).
  for (const std::string& folder : owned) {
    const fs::path top = root_ / folder;
    std::error_code ec;
    if (is_link(top) || !fs::is_directory(top, ec)) continue;
    std::vector<fs::path> dirs;
    for (auto it = fs::recursive_directory_iterator(top, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
      if (it->is_directory() && !it->is_symlink()) dirs.push_back(it->path());
    std::sort(dirs.rbegin(), dirs.rend());
    dirs.push_back(top);
    for (const fs::path& d : dirs)
      if (fs::is_empty(d, ec)) fs::remove(d, ec);
  }
  return removed;
}

}  // namespace nsg
