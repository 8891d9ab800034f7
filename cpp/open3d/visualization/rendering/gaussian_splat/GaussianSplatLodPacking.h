// CPU-side packing of a level-of-detail hierarchy for the GPU cut (docs/lod.md "The cut on
// the GPU"): the scene the renderer draws is every node of the hierarchy, leaves first (the
// source's splats in order), then the inner nodes; the cut chooses per frame which of them
// the projection sees. No Vulkan here: the record is GaussianSplatLodContract.h's.
#pragma once

#include <cstdint>
#include <vector>

#include "GaussianSplatLodContract.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SplatHierarchy.h"

namespace open3d {
namespace visualization {
namespace rendering {

struct PackedLodNodes {
    uint32_t num_leaves = 0;
    uint32_t num_inner = 0;
    std::vector<shader::GaussianLodNode> nodes;  ///< [num_leaves + num_inner], node order
    /// [num_leaves + num_inner - 1]: the inner nodes' children, inner nodes in order (node k's
    /// from nodes[N + k].first_child on, nodes[N + k].children of them).
    std::vector<uint32_t> children;
    /// Levels of the tree that hold inner nodes (the root's is level 0; 0 for a hierarchy of
    /// one leaf): the walk from the root takes one step per level.
    uint32_t inner_levels = 0;
};

/// Radius (3 x the largest scale, inner nodes), parent, child count and first child of every
/// node, and the children.
/// Throws core::Open3DError above 2^32 - 2 nodes (ids are uint32 on the GPU).
PackedLodNodes PackLodNodes(const t::geometry::SplatHierarchy& hierarchy);

/// Every node of `hierarchy` (built from `source`) as one splat cloud in node order: the
/// scene a renderer with the GPU cut uploads. Its first num_leaves splats are `source`'s.
t::geometry::PointCloud HierarchyNodeCloud(const t::geometry::SplatHierarchy& hierarchy,
                                           const t::geometry::PointCloud& source);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
