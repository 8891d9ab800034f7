// The level-of-detail cut on the GPU as a recorder (docs/lod.md "The cut on the GPU"): for a
// scene whose splats are a hierarchy's nodes (GaussianSplatLodPacking.h), dispatches of
// gaussian_lod_cut.comp turn the view and its budget (GaussianViewParams::lod_budget) into
// the list of the cut's nodes, in node order, that the projection reads slot by slot. Run by
// GaussianGeometryStage::Record before the projection; its counters land in
// GaussianGeometryStageCounters (lod_cut_nodes, lod_threshold).
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>

#include "GaussianSplatLodContract.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GpuTimestamps.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

/// What the cut reads and writes. Per view: buckets, histogram, mask, group counts and the
/// list (frames in flight must not share them); per scene: the nodes and positions.
struct LodCutBuffers {
    BufferRange view_params;   ///< shader::GaussianViewParams, already written
    BufferRange positions;     ///< vec4 [nodes]
    BufferRange nodes;         ///< shader::GaussianLodNode [nodes]
    BufferRange children;      ///< uint32 [nodes - 1]: the inner nodes' children, in order
    BufferRange buckets;       ///< uint32 [2 inner]: effective, then own buckets
    BufferRange histogram;     ///< uint32 [kLodBuckets]
    BufferRange counters;      ///< shader::GaussianGeometryStageCounters, already zeroed
    BufferRange visibility;    ///< uint32 [ceil(nodes / 32)]: the cut as bits
    BufferRange group_counts;  ///< uint32 [GroupCountsBytes / 4]
    BufferRange list;          ///< uint32 [list_slots], written: the cut's nodes
    /// uint32 [WalkBytes / 4]: the walk's state and visited nodes; also read by indirect
    /// dispatches.
    BufferRange walk;
    BufferRange previous;  ///< uint32 [1], per scene: the walk's last threshold
    uint32_t num_leaves = 0;
    uint32_t num_inner = 0;
    uint32_t list_slots = 0;  ///< shader::LodListSlots of the view's budget
    /// 0: size every inner node (the sizes, buckets and mask passes); else walk from the
    /// root through this many levels of inner nodes (PackedLodNodes::inner_levels). Only
    /// for a budget below the leaves (the walk never opens everything).
    uint32_t walk_levels = 0;
};

class GaussianLodCut {
public:
    explicit GaussianLodCut(const VulkanContext& context);

    /// Bytes of the per-view buffers for a hierarchy of `num_inner` inner nodes and
    /// `num_nodes` nodes in all.
    static VkDeviceSize BucketsBytes(uint32_t num_inner);
    static VkDeviceSize HistogramBytes();
    static VkDeviceSize VisibilityBytes(uint32_t num_nodes);
    static VkDeviceSize GroupCountsBytes(uint32_t num_nodes);
    /// The list for any budget: at most a slot per leaf.
    static VkDeviceSize ListBytes(uint32_t num_leaves);
    static VkDeviceSize WalkBytes(uint32_t num_inner);

    /// Records the cut: clears the histogram and the visibility words, then the passes with
    /// compute barriers between them (buffers.walk_levels picks the walk from the root or
    /// the passes over every inner node; both give the same cut). The caller orders the view
    /// parameters' and counters' writes before it and the list's compute write before the
    /// projection reads it.
    /// With `timestamps`, the passes that make the bits a list are timed as
    /// TimedPass::kLodCutList.
    void Record(VkCommandBuffer cmd, const LodCutBuffers& buffers,
                const GpuTimestamps* timestamps = nullptr) const;

private:
    void PushBindings(VkCommandBuffer cmd, const LodCutBuffers& buffers) const;
    void Dispatch(VkCommandBuffer cmd, uint32_t pass, uint32_t groups) const;
    void RecordWalk(VkCommandBuffer cmd, const LodCutBuffers& buffers) const;

    const VulkanContext& context_;
    uint32_t max_groups_x_;  // the device's maxComputeWorkGroupCount[0] (DispatchGridFor)
    UniqueDescriptorSetLayout set_layout_;
    UniquePipelineLayout pipeline_layout_;
    std::array<UniquePipeline, shader::kLodNumPasses> passes_;  // by kLodPass* value
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
