// Open3D's PointCloud methods that the C++ cloud lacks, for Python (docs/python.md "Open3D
// habits"): appending clouds, bounds, and a 4x4 transform that carries the
// Gaussian attributes along. Each throws core::Open3DError and leaves its input unchanged.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace pybind {

/// `a`'s points then `b`'s. Gaussian splat clouds merge as the renderer's scene does
/// (MergeGaussianSplatClouds: the higher SH degree, zero coefficients for the bands a cloud
/// lacks); any other attribute must be in both clouds with the same dtype and row shape.
t::geometry::PointCloud Append(const t::geometry::PointCloud& a, const t::geometry::PointCloud& b);

/// Per-axis minimum (`max` false) or maximum of the positions; zero for an empty cloud.
Eigen::Vector3d Bound(const t::geometry::PointCloud& cloud, bool max);

/// p' = A p + t for M = [A t; 0 0 0 1]. A cloud with Gaussian attributes takes only
/// A = s R (R a rotation, s a non-zero uniform scale, negative for a point inversion): the
/// splats are scaled by s (Scale) and rotated by R (Rotate: rot and SH follow), and the
/// positions become A p + t, so every splat keeps its look. A shear or a non-uniform scale has no
/// (rot, scale) per splat and is refused. Clouds without Gaussian attributes take any affine M
/// (positions only).
void TransformCloud(t::geometry::PointCloud& cloud, const Eigen::Matrix4d& transformation);

}  // namespace pybind
}  // namespace open3d
