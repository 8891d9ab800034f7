// Input files are checked with stat before they are opened: open() of a FIFO (named pipe)
// blocks until a writer appears, so a reader handed one would hang forever instead of
// saying what is wrong.
#pragma once

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "open3d/core/Exception.h"

namespace open3d {
namespace core {

/// What a special file of stat mode `mode` is, in words ("a FIFO", "a socket", "a character
/// device", "a block device", "a special file"); nullptr for a regular file or a folder.
inline const char* SpecialFileKind(mode_t mode) {
    if (S_ISREG(mode) || S_ISDIR(mode)) return nullptr;
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISSOCK(mode)) return "a socket";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    return "a special file";
}

/// Throws naming the file unless `filename` exists and is a regular file (or a link to one).
inline void RequireRegularFile(const std::string& filename) {
    struct stat info;
    if (::stat(filename.c_str(), &info) != 0) {
        ThrowError("Cannot open '{}': {}", filename, std::strerror(errno));
    }
    if (S_ISDIR(info.st_mode)) ThrowError("'{}' is a folder, not a file", filename);
    if (const char* kind = SpecialFileKind(info.st_mode)) {
        ThrowError("'{}' is {}, not a regular file; refusing to read it", filename, kind);
    }
}

}  // namespace core
}  // namespace open3d
