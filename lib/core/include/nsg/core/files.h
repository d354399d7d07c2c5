#pragma once
// Whole-file reads with errors that name the file.
#include <filesystem>
#include <string>

namespace nsg {

// Reads the whole file; throws IoError("<path>", "", "...") if missing or unreadable.
std::string read_file(const std::filesystem::path& path);
// Throws IoError naming `path` and `what` ("table", "map expansion", …) if it is not a file.
void require_file(const std::filesystem::path& path, const std::string& what);

}  // namespace nsg
