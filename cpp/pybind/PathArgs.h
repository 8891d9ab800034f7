// File names from Python: str or any os.PathLike (pathlib.Path) through pybind11's
// std::filesystem::path caster, and the error for a missing input file, which Python gets as
// open3d_gs.Open3DFileNotFoundError: both Open3DError and FileNotFoundError.
#pragma once

#include <filesystem>
#include <string>

#include "open3d/core/Exception.h"

namespace open3d {
namespace pybind {

/// An input path where nothing is (Module.cpp translates it).
class FileNotFound : public core::Open3DError {
public:
    FileNotFound(const std::string& message, const std::string& path)
        : core::Open3DError(message), path_(path) {}
    const std::string& Path() const { return path_; }

private:
    std::string path_;
};

/// The path as the library takes it (bytes as the file system has them).
inline std::string PathString(const std::filesystem::path& path) { return path.string(); }

/// PathString(path); throws FileNotFound ("Cannot open '...': no such file", the readers'
/// words) when nothing is at `path`, so that every reader reports a missing file alike.
std::string InputPath(const std::filesystem::path& path);

}  // namespace pybind
}  // namespace open3d
