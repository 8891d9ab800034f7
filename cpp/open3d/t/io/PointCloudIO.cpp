#include "open3d/t/io/PointCloudIO.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "open3d/core/Exception.h"
#include "open3d/t/io/FileFormats.h"

namespace open3d {
namespace t {
namespace io {
namespace {

std::string LowerExtension(const std::string& filename) {
    std::string ext = std::filesystem::path(filename).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

[[noreturn]] void UnknownExtension(const std::string& filename) {
    core::ThrowError("'{}': unknown extension '{}' (supported: .ply, .splat)", filename,
                     LowerExtension(filename));
}

}  // namespace

ReadPointCloudReport ReadPointCloud(const std::string& filename, geometry::PointCloud& cloud,
                                    const ReadPointCloudOptions& options) {
    const std::string ext = LowerExtension(filename);
    ReadPointCloudReport report;
    // Read into a temporary so a failure leaves the caller's cloud untouched.
    geometry::PointCloud result;
    if (ext == ".ply") {
        result = ReadPly(filename, options, report);
    } else if (ext == ".splat") {
        result = ReadSplat(filename, options, report);
    } else {
        UnknownExtension(filename);
    }
    cloud = std::move(result);
    return report;
}

void WritePointCloud(const std::string& filename, const geometry::PointCloud& cloud,
                     const WritePointCloudOptions& options) {
    const std::string ext = LowerExtension(filename);
    if (ext == ".ply") {
        WritePly(filename, cloud, options.ply_format);
    } else if (ext == ".splat") {
        WriteSplat(filename, cloud);
    } else {
        UnknownExtension(filename);
    }
}

}  // namespace io
}  // namespace t
}  // namespace open3d
