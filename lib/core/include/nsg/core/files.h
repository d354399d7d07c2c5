#pragma once
// Whole-file reads with errors that name the file.
#include <filesystem>
#include <string>

namespace nsg {

// Reads the whole file; throws IoError("<path>", "", "...") if missing or unreadable.
std::string read_file(const std::filesystem::path& path);

// True when `relative` names something inside the folder it is relative to: not empty,
// not absolute, no '..' component. Paths read from tables, manifests and records must be.
bool stays_inside(const std::string& relative);
// Throws IoError naming `path` and `what` ("table", "map expansion", …) if it is not a file.
void require_file(const std::filesystem::path& path, const std::string& what);

}  // namespace nsg
