#pragma once
// One owner of an output folder (a command's --out). Every command writes through it so
// that its rules hold in one place:
//   - files appear whole (a temp name in the same folder, then a rename: atomic_file.h);
//   - every path stays inside the folder: relative, no "..", and no symlink on the way
//     (a link planted in an earlier output, or in a stranger's folder, is never followed
//     out, neither to write nor to delete);
//   - a name that comes from data (scene, camera channel, key, location) becomes a path
//     component only through safe_name();
//   - replacing an earlier output removes only files a document of ours lists; any other
//     file in the folders we own is named and the run refused before anything is removed;
//   - --out is never an input folder, nor a folder that holds one.
#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "nsg/core/atomic_file.h"

namespace nsg {

// Longest file-name component most file systems take (ext4, XFS, APFS: 255 bytes).
inline constexpr size_t kMaxNameBytes = 255;

// `name` unchanged when it is safe as one file-name component; otherwise DataError naming
// `file` and `record` (e.g. "scene 'x' (token …)") with what was expected: not empty, not
// "." or "..", no '/', '\\', NUL or other control character, at most kMaxNameBytes bytes.
const std::string& safe_name(const std::string& name, const std::string& file, const std::string& record);

// True when `a` and `b` are one folder, or `inner` lies inside `outer`, after resolving
// links of the parts that exist (weakly_canonical).
bool same_folder(const std::filesystem::path& a, const std::filesystem::path& b);
bool inside_folder(const std::filesystem::path& inner, const std::filesystem::path& outer);

// ConfigError when `out` is `input` or holds it: the command would write over, or replace,
// what it reads. `input_option` names the flag that gave `input` ("--leaderboard", …).
void refuse_out_over_input(const std::filesystem::path& out, const std::filesystem::path& input,
                           const std::string& input_option, const std::string& out_option = "--out");

class OutputFolder {
 public:
  // `root` is the folder itself (it may be a link the user made; nothing below it may be).
  explicit OutputFolder(std::filesystem::path root, std::string option = "--out");

  const std::filesystem::path& root() const { return root_; }

  // The path of `relative` inside the folder, creating nothing. ConfigError naming the
  // option when `relative` is empty, absolute or holds "..", DataError when a part of it
  // that exists is a symlink (or, before the last part, not a folder).
  std::filesystem::path path(const std::string& relative) const;
  // As path(), after creating the folders that lead to it (none of them through a link).
  std::filesystem::path prepare(const std::string& relative) const;
  // Writes `bytes` to `relative` atomically (temp name + rename); kDeferred: durable at the
  // caller's flush_file_system(root()), before its manifest.
  void write(const std::string& relative, std::string_view bytes, Durability durability = Durability::kAtCommit) const;

  // The files (relative, '/'-separated, sorted) under the folders `owned` ("." = all of it),
  // walked without following links; a symlink or other non-regular entry is listed too.
  std::vector<std::string> files_under(const std::vector<std::string>& owned) const;

  // ConfigError unless every file under `owned` ("." = the whole folder) is in `listed` or
  // is a temp file of our writers: the check remove_listed makes before removing.
  void refuse_unlisted(const std::set<std::string>& listed, const std::vector<std::string>& owned,
                       const std::string& document) const;

  // Removes an earlier output of ours: every file under `owned` must be in `listed` (the
  // files a document we wrote lists, e.g. a manifest), or be a temp file one of our
  // writers left (name "<x>.tmp-<pid>-<n>"); otherwise ConfigError naming the first such
  // files, their count and `document` (what would have listed them), before anything is
  // removed. A listed path is removed only when it is found there as a regular file (a
  // listed "../x" or a link is never touched). Folders left empty are removed. Returns the
  // number of files removed.
  int64_t remove_listed(const std::set<std::string>& listed, const std::vector<std::string>& owned,
                        const std::string& document) const;

 private:
  std::filesystem::path root_;
  std::string option_;
};

// True for the temp names of atomic_file.h ("<target>.tmp-<pid>-<n>").
bool is_temp_name(const std::string& file_name);

}  // namespace nsg
