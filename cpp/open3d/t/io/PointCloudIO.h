// Reading and writing Gaussian splat clouds: 3DGS PLY (binary LE/BE, ASCII) and
// antimatter15 .splat. Failures throw core::Open3DError naming the file and the problem.
#pragma once

#include <cstdint>
#include <string>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace t {
namespace io {

struct ReadPointCloudOptions {
    /// Splats with NaN/Inf values are refused by default; true drops them instead
    /// (the count is reported in ReadPointCloudReport and logged).
    bool drop_non_finite = false;
};

struct ReadPointCloudReport {
    int64_t num_points = 0;
    int64_t dropped_non_finite = 0;
    int64_t trailing_bytes = 0;  // bytes after the declared vertices (warned, ignored)
};

/// Reads a .ply or .splat file (chosen by extension, case-insensitive). On failure
/// throws and leaves `cloud` unchanged.
ReadPointCloudReport ReadPointCloud(const std::string& filename, geometry::PointCloud& cloud,
                                    const ReadPointCloudOptions& options = {});

enum class PlyFormat { BinaryLittleEndian, BinaryBigEndian, Ascii };

struct WritePointCloudOptions {
    PlyFormat ply_format = PlyFormat::BinaryLittleEndian;
};

/// Writes a .ply (3DGS layout, log-scales) or .splat file. Writing a cloud with SH
/// degree > 0 to .splat drops f_rest with a warning (the format cannot hold it).
void WritePointCloud(const std::string& filename, const geometry::PointCloud& cloud,
                     const WritePointCloudOptions& options = {});

}  // namespace io
}  // namespace t
}  // namespace open3d
