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

// Paths a document keeps to folders outside itself (a dataset's release, a frames export's
// release) are written relative to the document's folder, so the two move together.
// `target` relative to `document_dir` (lexically; an empty `target` stays empty).
std::string path_relative_to(const std::filesystem::path& target, const std::filesystem::path& document_dir);
// A path read from a document in `document_dir`, resolved against that folder (an absolute one
// as is). Documents written before their paths were relative hold them relative to where the
// command ran: that reading is taken when only it names an existing folder.
std::filesystem::path resolve_document_path(const std::string& stored, const std::filesystem::path& document_dir);

}  // namespace nsg
