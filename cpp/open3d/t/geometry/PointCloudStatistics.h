// Robust summaries of a point cloud's positions, for framing a scene with a camera or
// sizing a marker mesh: medians and percentiles ignore the stray far-away splats that
// trained 3DGS scenes usually contain.
#pragma once

#include <Eigen/Core>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace t {
namespace geometry {

/// Per-axis median of the positions; zero for an empty cloud.
Eigen::Vector3d ComputeMedianCenter(const PointCloud& cloud);

/// The `fraction` quantile (0..1) of the distances of the positions from `center`, at least
/// 1e-3; 1 for an empty cloud.
double ComputeDistanceQuantile(const PointCloud& cloud, const Eigen::Vector3d& center,
                               double fraction);

}  // namespace geometry
}  // namespace t
}  // namespace open3d
