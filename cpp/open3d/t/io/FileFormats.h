// Internal to t/io: one reader and writer per file format; PointCloudIO dispatches here.
#pragma once

#include <cmath>
#include <string>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {

geometry::PointCloud ReadPly(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report);
void WritePly(const std::string& filename, const geometry::PointCloud& cloud, PlyFormat format);

geometry::PointCloud ReadSplat(const std::string& filename, const ReadPointCloudOptions& options,
                               ReadPointCloudReport& report);
void WriteSplat(const std::string& filename, const geometry::PointCloud& cloud);

/// The float32 log-scale whose exp (computed as the reader does, in double) gives back
/// `scale` exactly when such a value exists; otherwise the nearest one. Zero maps to a
/// finite log whose exp is zero.
float EncodeLogScale(float scale);
/// What the reader does: exp in double, rounded to float.
inline float DecodeLogScale(float log_scale) {
    return static_cast<float>(std::exp(static_cast<double>(log_scale)));
}

}  // namespace io
}  // namespace t
}  // namespace open3d
