#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianLodCut.h"

#include <algorithm>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/ComputePipeline.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/EmbeddedShaders.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

using namespace shader;

uint32_t DivCeil(uint64_t a, uint64_t b) { return static_cast<uint32_t>((a + b - 1) / b); }

void ComputeToCompute(VkCommandBuffer cmd) {
    RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

}  // namespace

GaussianLodCut::GaussianLodCut(const VulkanContext& context)
    : context_(context), max_groups_x_(context.GetDeviceInfo().max_compute_workgroups_x) {
    set_layout_ = CreateStorageBufferPushLayout(context, kLodNumBindings);
    pipeline_layout_ =
        CreatePipelineLayout(context, set_layout_.Get(), sizeof(GaussianLodPushConstants));
    const char* names[kLodNumPasses] = {
        "gaussian_lod_cut (sizes)",         "gaussian_lod_cut (buckets)",
        "gaussian_lod_cut (threshold)",     "gaussian_lod_cut (mask)",
        "gaussian_lod_cut (counts)",        "gaussian_lod_cut (offsets)",
        "gaussian_lod_cut (block offsets)", "gaussian_lod_cut (list)",
        "gaussian_lod_cut (walk start)",    "gaussian_lod_cut (walk)",
        "gaussian_lod_cut (walk mask)"};
    for (uint32_t pass = 0; pass < kLodNumPasses; ++pass) {
        const VkSpecializationMapEntry entry{kSpecLodPass, 0, sizeof(uint32_t)};
        const VkSpecializationInfo info{1, &entry, sizeof(uint32_t), &pass};
        passes_[pass] = CreateComputePipeline(context, pipeline_layout_.Get(),
                                              spirv::kGaussianLodCut, names[pass], &info);
    }
}

VkDeviceSize GaussianLodCut::BucketsBytes(uint32_t num_inner) {
    return VkDeviceSize(std::max(num_inner, 2u)) * 2 * 4;  // effective, then own
}

VkDeviceSize GaussianLodCut::HistogramBytes() { return VkDeviceSize(kLodBuckets) * 4; }

VkDeviceSize GaussianLodCut::VisibilityBytes(uint32_t num_nodes) {
    return VkDeviceSize(std::max(DivCeil(num_nodes, 32), 4u)) * 4;
}

VkDeviceSize GaussianLodCut::GroupCountsBytes(uint32_t num_nodes) {
    return VkDeviceSize(std::max(LodCountWords(num_nodes), 1u)) * 4;
}

VkDeviceSize GaussianLodCut::ListBytes(uint32_t num_leaves) {
    return VkDeviceSize(std::max(num_leaves, 1u)) * 4;
}

VkDeviceSize GaussianLodCut::WalkBytes(uint32_t num_inner) {
    // Each round appends an inner node at most once (a tree), the root included.
    return (VkDeviceSize(kLodWalkHeaderWords) + std::max(num_inner, 1u)) * 4;
}

void GaussianLodCut::PushBindings(VkCommandBuffer cmd, const LodCutBuffers& buffers) const {
    const std::array<const BufferRange*, kLodNumBindings> ranges{
        &buffers.view_params, &buffers.positions, &buffers.nodes,      &buffers.buckets,
        &buffers.histogram,   &buffers.counters,  &buffers.visibility, &buffers.group_counts,
        &buffers.list,        &buffers.children,  &buffers.walk,       &buffers.previous};
    static_assert(
        kLodViewBinding == 0 && kLodPositionsBinding == 1 && kLodNodesBinding == 2 &&
            kLodBucketsBinding == 3 && kLodHistogramBinding == 4 && kLodCountersBinding == 5 &&
            kLodVisibilityBinding == 6 && kLodGroupCountsBinding == 7 && kLodListBinding == 8 &&
            kLodChildrenBinding == 9 && kLodWalkBinding == 10 && kLodPreviousBinding == 11,
        "ranges above are listed in binding order");
    std::array<VkDescriptorBufferInfo, kLodNumBindings> infos{};
    std::array<VkWriteDescriptorSet, kLodNumBindings> writes{};
    for (uint32_t i = 0; i < kLodNumBindings; ++i) {
        const BufferRange& range = *ranges[i];
        if (range.buffer == VK_NULL_HANDLE) {
            core::ThrowError("GaussianLodCut: binding {} has no buffer", i);
        }
        infos[i] = {range.buffer, range.offset, range.size};
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    context_.GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_.Get(),
                                       0, kLodNumBindings, writes.data());
}

void GaussianLodCut::Dispatch(VkCommandBuffer cmd, uint32_t pass, uint32_t groups) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, passes_[pass].Get());
    const uvec4 grid = DispatchGridFor(groups, max_groups_x_);
    RecordDispatch(cmd, grid.x, grid.y, 1);
}

void GaussianLodCut::RecordWalk(VkCommandBuffer cmd, const LodCutBuffers& buffers) const {
    const auto walk_indirect = [&](uint32_t pass, uint32_t args_word) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, passes_[pass].Get());
        RecordDispatchIndirect(cmd, buffers.walk.buffer,
                               buffers.walk.offset + VkDeviceSize(args_word) * 4);
    };
    Dispatch(cmd, kLodPassWalkStart, 1);
    // Two rounds are recorded; a first round that finds the threshold turns the second's
    // dispatches to zero workgroups (kLodWalkDone).
    // The walk's passes write the arguments of the indirect dispatches that follow them.
    for (int round = 0; round < 2; ++round) {
        for (uint32_t level = 0; level < buffers.walk_levels; ++level) {
            RecordComputeToComputeAndIndirect(cmd);
            walk_indirect(kLodPassWalk, kLodWalkArgs);
        }
        RecordComputeToComputeAndIndirect(cmd);
        Dispatch(cmd, kLodPassThreshold, 1);
        if (round == 0) {
            // The second round's histogram starts from zero; after a first round that found
            // the threshold nothing reads it again.
            RecordMemoryBarrier(
                cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
            vkCmdFillBuffer(cmd, buffers.histogram.buffer, buffers.histogram.offset,
                            HistogramBytes(), 0u);
            RecordMemoryBarrier(
                cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
    }
    RecordComputeToComputeAndIndirect(cmd);
    walk_indirect(kLodPassWalkMask, kLodWalkMaskArgs);
}

void GaussianLodCut::Record(VkCommandBuffer cmd, const LodCutBuffers& buffers,
                            const GpuTimestamps* timestamps) const {
    const uint32_t nodes = buffers.num_leaves + buffers.num_inner;
    const bool walk = buffers.walk_levels > 0;
    if (walk && (buffers.num_inner == 0 || buffers.list_slots >= buffers.num_leaves)) {
        core::ThrowError("GaussianLodCut: a walk needs inner nodes and a budget below the leaves");
    }
    vkCmdFillBuffer(cmd, buffers.histogram.buffer, buffers.histogram.offset, HistogramBytes(), 0u);
    vkCmdFillBuffer(cmd, buffers.visibility.buffer, buffers.visibility.offset,
                    VisibilityBytes(nodes), 0u);
    RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    PushBindings(cmd, buffers);
    const GaussianLodPushConstants push{buffers.num_leaves, buffers.num_inner, buffers.list_slots,
                                        walk ? 1u : 0u, max_groups_x_};
    vkCmdPushConstants(cmd, pipeline_layout_.Get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push),
                       &push);
    // A hierarchy of one splat has no inner node: the sizes and buckets passes do nothing,
    // the histogram stays zero and the threshold pass opens everything (the one leaf).
    const uint32_t inner_groups = std::max(DivCeil(buffers.num_inner, kLodWorkgroupSize), 1u);
    if (walk) {
        RecordWalk(cmd, buffers);
    } else {
        const uint32_t first_passes[] = {kLodPassSizes, kLodPassBuckets, kLodPassThreshold,
                                         kLodPassMask};
        for (const uint32_t pass : first_passes) {
            if (pass != kLodPassSizes) ComputeToCompute(cmd);
            Dispatch(cmd, pass, pass == kLodPassThreshold ? 1u : inner_groups);
        }
    }
    // The mask becomes the list in node order.
    ComputeToCompute(cmd);
    if (timestamps) timestamps->RecordBegin(cmd, TimedPass::kLodCutList);
    Dispatch(cmd, kLodPassCounts, std::max(DivCeil(LodGroups(nodes), kLodWorkgroupSize), 1u));
    ComputeToCompute(cmd);
    Dispatch(cmd, kLodPassOffsets, std::max(LodBlocks(nodes), 1u));
    ComputeToCompute(cmd);
    Dispatch(cmd, kLodPassBlockOffsets, 1u);
    ComputeToCompute(cmd);
    Dispatch(cmd, kLodPassList, std::max(DivCeil(DivCeil(nodes, 32), kLodWorkgroupSize), 1u));
    if (timestamps) timestamps->RecordEnd(cmd, TimedPass::kLodCutList);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
