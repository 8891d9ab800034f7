// Selecting splats in a view by a screen region (docs/editing.md "Selection in a view"): the
// splats whose projected centre falls inside a polygon (a rectangle or a lasso) and that the
// view shows there, as the CPU reference composites it.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

/// The four corners of the rectangle [x0, x1] x [y0, y1] (pixels; corners in either order).
std::vector<Eigen::Vector2d> RectanglePolygon(double x0, double y0, double x1, double y1);

/// Whether point p lies inside the closed polygon (even-odd rule; at least 3 vertices).
bool PolygonContains(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p);

/// Indices (ascending) of the splats of `cloud` whose centre projects inside `polygon` (pixel
/// coordinates, pixel (u, v) centred at (u, v)) and that contribute a blend weight alpha T of at
/// least 1/255 to some pixel whose centre lies inside it, under the reference's rules (near cull,
/// tile culling, the transmittance stop). With `include_occluded`, every splat whose centre
/// projects inside (in front of the near plane) instead: what lies behind, and splats too faint
/// to show. Throws core::Open3DError for a polygon of fewer than 3 vertices or a non-finite one.
std::vector<int64_t> SelectSplatsInView(const t::geometry::PointCloud& cloud,
                                        const camera::PinholeCamera& camera,
                                        const RenderConfig& config,
                                        const std::vector<Eigen::Vector2d>& polygon,
                                        bool include_occluded = false);

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
