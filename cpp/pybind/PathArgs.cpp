#include "PathArgs.h"

#include <system_error>

namespace open3d {
namespace pybind {

std::string InputPath(const std::filesystem::path& path) {
    std::error_code error;
    // status() follows links: a dangling link names nothing either. A loop of links or a
    // folder without permission is another error, left to the reader to name.
    const auto status = std::filesystem::status(path, error);
    if (status.type() == std::filesystem::file_type::not_found) {
        const std::string name = PathString(path);
        throw FileNotFound(fmt::format("Cannot open '{}': no such file", name), name);
    }
    return PathString(path);
}

}  // namespace pybind
}  // namespace open3d
