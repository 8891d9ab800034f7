// Placeholder until the format is implemented: every call throws.
#include "open3d/core/Exception.h"
#include "open3d/t/io/FileFormats.h"

namespace open3d {
namespace t {
namespace io {

geometry::PointCloud ReadSpz(const std::string& filename, const ReadPointCloudOptions&,
                             ReadPointCloudReport&) {
    core::ThrowError("'{}': reading this format is not implemented yet", filename);
}

void WriteSpz(const std::string& filename, const geometry::PointCloud&) {
    core::ThrowError("'{}': writing this format is not implemented yet", filename);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
