#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatLodPacking.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {
namespace rendering {

bool WalksLodCut(LodCutSearch search, uint32_t num_inner, uint32_t num_leaves,
                 uint32_t list_slots) {
    if (num_inner == 0 || list_slots >= num_leaves) return false;
    switch (search) {
        case LodCutSearch::kEveryNode:
            return false;
        case LodCutSearch::kFromRoot:
            return true;
        case LodCutSearch::kAuto:
            return num_inner >= kLodWalkMinInner && list_slots <= num_inner / 4;
    }
    return false;
}

PackedLodNodes PackLodNodes(const t::geometry::SplatHierarchy& hierarchy) {
    const int64_t total = hierarchy.NumNodes();
    if (total <= 0 || total >= int64_t(shader::kLodNoParent)) {
        core::ThrowError("PackLodNodes: {} nodes; the GPU cut takes 1 to {}", total,
                         int64_t(shader::kLodNoParent) - 1);
    }
    PackedLodNodes packed;
    packed.num_leaves = static_cast<uint32_t>(hierarchy.num_leaves);
    packed.num_inner = static_cast<uint32_t>(hierarchy.NumInner());
    packed.nodes.assign(static_cast<size_t>(total),
                        shader::GaussianLodNode{0.0f, shader::kLodNoParent, 0u, 0u});
    const float* scale =
        hierarchy.NumInner() > 0 ? hierarchy.inner.GetGaussianSplatArrays().scale : nullptr;
    for (int64_t k = 0; k < hierarchy.NumInner(); ++k) {
        shader::GaussianLodNode& node = packed.nodes[size_t(hierarchy.num_leaves + k)];
        const float* s = scale + 3 * k;
        node.radius = 3.0f * std::max({std::abs(s[0]), std::abs(s[1]), std::abs(s[2])});
        const int64_t begin = hierarchy.child_offsets[size_t(k)];
        const int64_t end = hierarchy.child_offsets[size_t(k) + 1];
        node.children = static_cast<uint32_t>(end - begin);
        node.first_child = static_cast<uint32_t>(begin);
        for (int64_t c = begin; c < end; ++c) {
            packed.nodes[size_t(hierarchy.children[size_t(c)])].parent =
                static_cast<uint32_t>(hierarchy.num_leaves + k);
        }
    }
    // Parents come after their children (the root last), so a walk down from the end sees
    // each parent's depth before its children's.
    std::vector<uint32_t> depth(size_t(hierarchy.NumInner()), 0u);
    for (int64_t k = hierarchy.NumInner() - 1; k >= 0; --k) {
        const uint32_t parent = packed.nodes[size_t(hierarchy.num_leaves + k)].parent;
        if (parent != shader::kLodNoParent) {
            depth[size_t(k)] = depth[size_t(parent - packed.num_leaves)] + 1;
        }
        packed.inner_levels = std::max(packed.inner_levels, depth[size_t(k)] + 1);
    }
    packed.children.resize(hierarchy.children.size());
    std::transform(hierarchy.children.begin(), hierarchy.children.end(), packed.children.begin(),
                   [](int64_t id) { return static_cast<uint32_t>(id); });
    return packed;
}

t::geometry::PointCloud HierarchyNodeCloud(const t::geometry::SplatHierarchy& hierarchy,
                                           const t::geometry::PointCloud& source) {
    std::vector<int64_t> all(static_cast<size_t>(hierarchy.NumNodes()));
    std::iota(all.begin(), all.end(), int64_t(0));
    return t::geometry::ExtractSplatNodes(hierarchy, source, all);
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
