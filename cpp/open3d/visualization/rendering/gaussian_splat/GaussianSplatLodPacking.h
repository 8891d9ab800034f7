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
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

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

/// Whether the GPU cut walks from the root (RenderConfig::lod_cut_search) for a hierarchy of
/// `num_inner` inner nodes and `num_leaves` leaves whose view has `list_slots` slots
/// (shader::LodListSlots of its budget). Never when the slots hold every leaf (the walk never
/// opens everything). kAuto: from kLodWalkMinInner inner nodes, for list_slots up to a quarter
/// of them (H200: the 12.2M inner nodes of a 24.5M-splat grid cut in 0.85 ms walking against
/// 1.21 ms at 2.45M, 1.67 against 1.37 at 9.8M; docs/lod.md).
bool WalksLodCut(LodCutSearch search, uint32_t num_inner, uint32_t num_leaves, uint32_t list_slots);

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
