#pragma once
// What built this binary, for score receipts: the version (nsg/core/version.h) and the
// commit of the source tree.
namespace nsg {

// The git commit the build's source tree was at, "<sha>-dirty" when tracked files had
// changes, "unknown" when it was not a git checkout (cmake/GitCommit.cmake).
const char* git_commit();

}  // namespace nsg
