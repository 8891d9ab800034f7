// Input paths of the command-line apps: why a path given as an input cannot be read, in
// words a user can act on (a symbolic-link loop is not "does not exist").
#pragma once

#include <string>

namespace open3d {
namespace t {
namespace io {

/// "" when `path` names a readable file (or, with `folder_ok`, a readable folder: a SOG
/// folder); else why not: "does not exist", "is a loop of symbolic links", "is a folder",
/// "is a FIFO, not a regular file" (or a socket, a device), "cannot be read (permission
/// denied)", each after the quoted path.
std::string InputPathProblem(const std::string& path, bool folder_ok);

}  // namespace io
}  // namespace t
}  // namespace open3d
