// CLI11 validators of the apps' input paths: t::io::InputPathProblem's words (a loop of
// symbolic links, a folder, no permission) instead of CLI11's "Path does not exist" for all.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "open3d/t/io/InputPaths.h"

namespace open3d {
namespace apps {

/// A readable file, or a readable folder with `folder_ok` (a SOG folder). The names are
/// CLI11's own, so --help reads as before.
inline CLI::Validator ReadableInput(bool folder_ok) {
    return CLI::Validator(
        [folder_ok](std::string& path) { return t::io::InputPathProblem(path, folder_ok); },
        folder_ok ? "PATH(existing)" : "FILE");
}

}  // namespace apps
}  // namespace open3d
