#include "open3d/t/io/OutputFiles.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"

namespace open3d {
namespace t {
namespace io {

namespace fs = std::filesystem;

namespace {

// The folder a path is created in ("." for a bare file name).
fs::path FolderOf(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? fs::path(".") : parent;
}

}  // namespace

void CheckOutputPath(const std::string& what, const std::string& path) {
    if (path.empty()) core::ThrowError("{}: the output path is empty", what);
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        core::ThrowError("{} '{}' is a folder; give a file name", what, path);
    }
    const fs::path folder = FolderOf(path);
    if (!fs::is_directory(folder, ec)) {
        core::ThrowError("{} '{}': the folder '{}' does not exist", what, path, folder.string());
    }
    if (::access(folder.c_str(), W_OK) != 0) {
        core::ThrowError("{} '{}': the folder '{}' is not writable: {}", what, path,
                         folder.string(), std::strerror(errno));
    }
}

std::string LowerCaseExtension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    if (!ext.empty()) ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

bool SameOutputPath(const std::string& a, const std::string& b) {
    // weakly_canonical resolves symbolic links and "." / ".." in the part that exists.
    std::error_code ec_a, ec_b;
    const fs::path pa = fs::weakly_canonical(fs::absolute(a), ec_a);
    const fs::path pb = fs::weakly_canonical(fs::absolute(b), ec_b);
    if (ec_a || ec_b) {
        return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
    }
    return pa == pb;
}

void CheckOutputIsNotAnInput(const std::string& what, const std::string& output,
                             const std::vector<NamedInput>& inputs) {
    if (output.empty()) return;
    for (const NamedInput& input : inputs) {
        if (input.path.empty()) continue;
        std::error_code ec;
        // equivalent() also catches a hard link; it needs both files to exist.
        const bool same = SameOutputPath(output, input.path) ||
                          (fs::exists(output, ec) && fs::equivalent(output, input.path, ec));
        if (same) {
            core::ThrowError(
                "{} '{}' is the {} file '{}': an input is never overwritten; write the output "
                "elsewhere",
                what, output, input.flag, input.path);
        }
    }
}

OutputFileSet::~OutputFileSet() {
    for (const auto& [temporary, final_path] : files_) std::remove(temporary.c_str());
}

std::string OutputFileSet::Add(const std::string& final_path) {
    const fs::path folder = FolderOf(final_path);
    const std::string name = fs::path(final_path).filename().string();
    // O_EXCL makes the name ours even with several runs writing to one folder; mode 0666
    // (less the umask) gives the final file the permissions a plain create would.
    for (int attempt = 0; attempt < 100; ++attempt) {
        const std::string temporary =
            (folder / (".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(files_.size()) +
                       "-" + std::to_string(attempt) + "-" + name))
                .string();
        const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0666);
        if (fd >= 0) {
            ::close(fd);
            files_.emplace_back(temporary, final_path);
            return temporary;
        }
        if (errno != EEXIST) {
            core::ThrowError("cannot create a temporary file in '{}' for '{}': {}", folder.string(),
                             final_path, std::strerror(errno));
        }
    }
    core::ThrowError("cannot create a temporary file in '{}' for '{}': too many exist",
                     folder.string(), final_path);
}

void OutputFileSet::Write(const std::string& final_path,
                          const std::function<void(const std::string& temporary)>& write) {
    const std::string temporary = Add(final_path);
    // Warnings the writer logs and its error name the user's file (the whole path, then the
    // bare name: some writers name only that), never the temporary.
    const core::ScopedLogAlias path_alias(temporary, final_path);
    const core::ScopedLogAlias name_alias(fs::path(temporary).filename().string(),
                                          fs::path(final_path).filename().string());
    try {
        write(temporary);
    } catch (const core::Open3DError& e) {
        // The failed output leaves the set: a later Commit must not publish its remains.
        std::remove(temporary.c_str());
        files_.pop_back();
        throw core::Open3DError(core::ApplyLogAliases(e.what()));
    }
}

void OutputFileSet::Commit() {
    // Every output is complete before the first rename, so a failed write earlier leaves
    // none of them; only a failing rename (the folder removed meanwhile) can split the set.
    for (const auto& [temporary, final_path] : files_) {
        if (std::rename(temporary.c_str(), final_path.c_str()) != 0) {
            core::ThrowError("cannot rename '{}' to '{}': {}", temporary, final_path,
                             std::strerror(errno));
        }
    }
    files_.clear();
}

}  // namespace io
}  // namespace t
}  // namespace open3d
