// Concatenating several splat clouds into one (the merged scene a backend uploads once for
// all objects of a FilamentScene; docs/filament.md "Scene").
#pragma once

#include <vector>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace visualization {
namespace rendering {

/// Splats of `clouds` in order, in one cloud. The SH degree is the highest of the inputs;
/// clouds of a lower degree get zero coefficients for the missing bands (which adds
/// nothing to their colour). Throws core::Open3DError when a cloud is not a valid splat
/// cloud or the list is empty.
t::geometry::PointCloud MergeGaussianSplatClouds(
    const std::vector<const t::geometry::PointCloud*>& clouds);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
