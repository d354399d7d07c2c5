#pragma once
// A cheap private copy of the cached synthetic release for one corruption: every file is a
// hard link (a symlink across file systems), so a case costs no 60 MB copy. Edits go
// through the members below, which first replace the link by a file of their own, so the
// shared release is never touched.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::test {

inline constexpr const char* kVersion = "v1.0-mini";

class ReleaseCopy {
 public:
  ReleaseCopy(const std::filesystem::path& source, const std::filesystem::path& root);

  const std::filesystem::path& root() const { return root_; }
  std::filesystem::path table_path(const std::string& table) const;

  nlohmann::ordered_json table(const std::string& table) const;
  // Writes the table back. `text_edits` are applied to the dumped text ({from, to}, every
  // occurrence): how NaN, Infinity and wrong-typed values that JSON cannot hold get in.
  void put_table(const std::string& table, const nlohmann::ordered_json& rows,
                 const std::vector<std::pair<std::string, std::string>>& text_edits = {});

  std::string read(const std::string& relative) const;
  // Replaces the file (never writing through the link).
  void write(const std::string& relative, const std::string& bytes);
  void remove(const std::string& relative);

  // The first sample_data row (file order) matching the predicate's fileformat / key-frame
  // flag / filename prefix ("samples/LIDAR_TOP/").
  nlohmann::ordered_json sample_data(const std::string& fileformat, bool key_frame,
                                     const std::string& prefix = "") const;
  // Every key-frame sample_data filename under `prefix`.
  std::vector<std::string> key_frame_files(const std::string& prefix) const;

 private:
  std::filesystem::path root_;
};

}  // namespace nsg::test
