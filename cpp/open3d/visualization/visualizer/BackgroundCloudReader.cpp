#include "open3d/visualization/visualizer/BackgroundCloudReader.h"

#include <fmt/format.h>

#include <filesystem>
#include <system_error>

#include "open3d/core/Exception.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace visualization {

BackgroundCloudReader::~BackgroundCloudReader() {
    if (future_.valid()) future_.wait();
}

void BackgroundCloudReader::Start(const std::string& path) {
    if (IsBusy()) core::ThrowError("{}: still reading {}", path, path_);
    path_ = path;
    std::error_code error;
    const auto bytes = std::filesystem::is_regular_file(path, error)
                           ? std::filesystem::file_size(path, error)
                           : std::uintmax_t(0);
    size_mb_ = error ? 0.0 : double(bytes) / 1e6;
    start_ = std::chrono::steady_clock::now();
    future_ = std::async(std::launch::async, [path] {
        t::geometry::PointCloud cloud;
        t::io::ReadPointCloud(path, cloud);
        t::io::RequireGaussianSplat(path, cloud);
        return cloud;
    });
}

std::optional<t::geometry::PointCloud> BackgroundCloudReader::TakeResult() {
    if (!future_.valid() ||
        future_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
        return std::nullopt;
    }
    return future_.get();  // leaves the future empty, also when it throws
}

std::string BackgroundCloudReader::Describe() const {
    if (!IsBusy()) return "";
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const std::string name = std::filesystem::path(path_).filename().string();
    return size_mb_ > 0.0 ? fmt::format("Loading {} ({:.1f} MB), {:.1f} s", name, size_mb_, seconds)
                          : fmt::format("Loading {}, {:.1f} s", name, seconds);
}

}  // namespace visualization
}  // namespace open3d
