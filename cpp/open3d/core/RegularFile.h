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

/// Throws naming the file unless `filename` exists and is a regular file (or a link to one).
inline void RequireRegularFile(const std::string& filename) {
    struct stat info;
    if (::stat(filename.c_str(), &info) != 0) {
        ThrowError("Cannot open '{}': {}", filename, std::strerror(errno));
    }
    if (S_ISDIR(info.st_mode)) ThrowError("'{}' is a folder, not a file", filename);
    if (!S_ISREG(info.st_mode)) {
        ThrowError("'{}' is not a regular file (a FIFO, device or socket); refusing to read it",
                   filename);
    }
}

}  // namespace core
}  // namespace open3d
