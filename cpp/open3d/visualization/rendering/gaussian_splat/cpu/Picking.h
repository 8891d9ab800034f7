// Picking a pixel of a view (docs/editing.md "Picking"): the splat that contributes most to it
// and the 3D point at its depth, as the CPU reference composites it.
#pragma once

#include <Eigen/Core>

#include <cstdint>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

struct PickResult {
    bool hit = false;  ///< some splat blends at the pixel
    /// The splat with the largest blend weight alpha T at the pixel (the first of equal ones,
    /// front to back), its weight, and the pixel's accumulated alpha 1 - T.
    int64_t splat = -1;
    double weight = 0.0;
    double alpha = 0.0;
    /// The pixel's expected depth sum(w z) / sum(w) and median depth (the splat that brings
    /// 1 - T to 0.5; 0 when it never does), view-space z, as the depth images hold them.
    double expected_depth = 0.0;
    double median_depth = 0.0;
    /// The world point on the pixel's ray (through its centre) at the expected depth.
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

/// Picks pixel (x, y) (integers, pixel centres) of `camera`'s view of `cloud`. Throws
/// core::Open3DError for a pixel outside the image.
PickResult PickPixel(const t::geometry::PointCloud& cloud, const camera::PinholeCamera& camera,
                     const RenderConfig& config, int x, int y);

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
