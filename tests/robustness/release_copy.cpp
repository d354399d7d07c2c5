#include "release_copy.h"

#include <fstream>
#include <stdexcept>

#include "nsg/core/files.h"

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace nsg::test {

namespace {
void link_tree(const fs::path& from, const fs::path& to) {
  fs::create_directories(to);
  for (const auto& e : fs::recursive_directory_iterator(from)) {
    const fs::path target = to / fs::relative(e.path(), from);
    if (e.is_directory()) {
      fs::create_directories(target);
      continue;
    }
    std::error_code ec;
    fs::create_hard_link(e.path(), target, ec);
    if (ec) fs::create_symlink(fs::absolute(e.path()), target);
  }
}

void replace_text(std::string& text, const std::string& from, const std::string& to) {
  size_t hits = 0;
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
    ++hits;
  }
  if (hits == 0) throw std::runtime_error("text edit found no '" + from + "'");
}
}  // namespace

ReleaseCopy::ReleaseCopy(const fs::path& source, const fs::path& root) : root_(root) { link_tree(source, root_); }

fs::path ReleaseCopy::table_path(const std::string& table) const { return root_ / kVersion / (table + ".json"); }

json ReleaseCopy::table(const std::string& table) const { return json::parse(read_file(table_path(table))); }

void ReleaseCopy::put_table(const std::string& table, const json& rows,
                            const std::vector<std::pair<std::string, std::string>>& text_edits) {
  std::string text = rows.dump(1);
  for (const auto& [from, to] : text_edits) replace_text(text, from, to);
  write(fs::relative(table_path(table), root_).string(), text);
}

std::string ReleaseCopy::read(const std::string& relative) const { return read_file(root_ / relative); }

void ReleaseCopy::write(const std::string& relative, const std::string& bytes) {
  const fs::path path = root_ / relative;
  fs::remove(path);  // break the link first: the shared release must stay intact
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

void ReleaseCopy::remove(const std::string& relative) {
  if (!fs::remove(root_ / relative)) throw std::runtime_error("nothing to remove at " + relative);
}

json ReleaseCopy::sample_data(const std::string& fileformat, bool key_frame, const std::string& prefix) const {
  for (const json& row : table("sample_data"))
    if (row["fileformat"] == fileformat && row["is_key_frame"] == key_frame &&
        row["filename"].get<std::string>().rfind(prefix, 0) == 0)
      return row;
  throw std::runtime_error("no sample_data row of format " + fileformat + " under '" + prefix + "'");
}

std::vector<std::string> ReleaseCopy::key_frame_files(const std::string& prefix) const {
  std::vector<std::string> files;
  for (const json& row : table("sample_data"))
    if (row["is_key_frame"] == true && row["filename"].get<std::string>().rfind(prefix, 0) == 0)
      files.push_back(row["filename"].get<std::string>());
  return files;
}

}  // namespace nsg::test
