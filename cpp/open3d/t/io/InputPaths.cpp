#include "open3d/t/io/InputPaths.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "open3d/core/RegularFile.h"

namespace open3d {
namespace t {
namespace io {

namespace fs = std::filesystem;

std::string InputPathProblem(const std::string& path, bool folder_ok) {
    const std::string quoted = "'" + path + "'";
    if (path.empty()) return "an empty path";
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec) {
        if (ec.value() == ELOOP) return quoted + " is a loop of symbolic links";
        if (ec.value() == ENOENT || ec.value() == ENOTDIR) return quoted + " does not exist";
        return quoted + ": " + ec.message();
    }
    if (!fs::exists(status)) {
        std::error_code link_ec;
        if (fs::is_symlink(fs::symlink_status(path, link_ec))) {
            return quoted + " is a symbolic link to nothing";
        }
        return quoted + " does not exist";
    }
    if (fs::is_directory(status) && !folder_ok) return quoted + " is a folder, not a file";
    // Reading a FIFO blocks until a writer comes, a device may never end: never open them.
    struct stat info;
    if (::stat(path.c_str(), &info) == 0) {
        if (const char* kind = core::SpecialFileKind(info.st_mode)) {
            return quoted + " is " + kind + ", not a regular file";
        }
    }
    if (::access(path.c_str(), R_OK) != 0) {
        return quoted + " cannot be read (" + std::strerror(errno) + ")";
    }
    return "";
}

}  // namespace io
}  // namespace t
}  // namespace open3d
