#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianGeometryStageRunner.h"
#include "open3d/core/Timer.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianCompositeStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

// Copies [0, bytes) of `src` into a fresh readback buffer after a compute -> transfer
// barrier the caller recorded, in the same command buffer.
struct PendingCopy {
    Buffer staging;
    void* destination;
    VkDeviceSize bytes;
};

void RecordCopy(const VulkanContext& context, VkCommandBuffer cmd, const Buffer& src,
                VkDeviceSize bytes, void* destination, std::vector<PendingCopy>& pending) {
    if (bytes == 0) return;
    Buffer staging(context, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::kHostReadback);
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd, src.Get(), staging.Get(), 1, &region);
    pending.push_back({std::move(staging), destination, bytes});
}

void FinishCopies(std::vector<PendingCopy>& pending) {
    for (PendingCopy& copy : pending) {
        std::memcpy(copy.destination, copy.staging.GetMapped(), copy.bytes);
    }
    pending.clear();
}

void ComputeToTransferBarrier(VkCommandBuffer cmd) {
    RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                        VK_ACCESS_2_TRANSFER_READ_BIT);
}

const char* FlagMessage(uint32_t bit) {
    return bit == kEntriesDropped
               ? "tile entries were dropped (a splat touches more than max_tiles_per_splat "
                 "tiles or the entries exceed max_tile_entries_total / the allocation)"
               : "Geometry stage counts were clamped to the allocated tile-entry capacity";
}

}  // namespace

RenderStats GeometryStageReadback::ToStats() const {
    RenderStats stats;
    stats.num_splats = num_splats;
    stats.num_visible = counters.visible_count;
    stats.num_tile_entries = counters.entry_count;
    stats.error_flags = counters.error_flags;
    stats.geometry_ms = geometry_stage_ms;
    return stats;
}

GaussianGeometryStageRunner::GaussianGeometryStageRunner(const VulkanContext& context,
                                                         const PackedGaussianSplats& packed,
                                                         uint32_t entry_capacity,
                                                         GeometryStageOptions options)
    : context_(context), pool_(context), geometry_stage_(context, options) {
    resources_.UploadScene(context, pool_, packed);
    resources_.AllocateView(context, entry_capacity);
}

void GaussianGeometryStageRunner::SetVisibility(const std::vector<uint32_t>& mask) {
    resources_.UploadVisibility(context_, pool_, mask);
}

GeometryStageReadback GaussianGeometryStageRunner::Run(const camera::PinholeCamera& camera,
                                                       const RenderConfig& config,
                                                       bool read_projected) {
    const PackedView packed_view = resources_.ViewParams(camera, config);
    const GeometryStageSceneBuffers scene = resources_.Scene();
    GeometryStageViewBuffers view = resources_.View();
    // Per-tile bins leave their ranges in the composite's state buffer.
    Buffer tile_ranges(
        context_,
        GaussianCompositeStage::StateBytes(uint32_t(camera.width), uint32_t(camera.height)),
        GaussianCompositeStage::GetStorageRequirements().state_usage, MemoryUsage::kDevice);
    view.tile_ranges = tile_ranges.Range();

    GeometryStageReadback out;
    out.num_splats = resources_.Layout().num_splats;
    std::vector<PendingCopy> pending;
    {
        CommandBuffer cmd = pool_.Allocate();
        cmd.Begin();
        geometry_stage_.Record(cmd.Get(), scene, view, packed_view);
        ComputeToTransferBarrier(cmd.Get());
        RecordCopy(context_, cmd.Get(), resources_.ViewResources().counters, sizeof(out.counters),
                   &out.counters, pending);
        cmd.End();
        UniqueFence fence = CreateFence(context_);
        const auto start = std::chrono::steady_clock::now();
        Submit(context_, cmd.Get(), fence.Get());
        Wait(context_, fence.Get());
        out.geometry_stage_ms = core::MillisecondsSince(start);
        FinishCopies(pending);
    }

    // Error flags are read after the fence and reported once per view (this runner).
    const uint32_t new_flags = out.counters.error_flags & ~warned_flags_;
    for (uint32_t bit : {kEntriesDropped, kCountsClamped}) {
        if (new_flags & bit)
            core::LogWarning("Gaussian splat geometry stage (Vulkan): {}", FlagMessage(bit));
    }
    warned_flags_ |= out.counters.error_flags;

    // Second copy with the sizes now known: only the live part of each buffer.
    const uint32_t visible = out.counters.visible_count;
    const uint32_t entries = out.counters.entry_count;
    // Per-tile bins sort no visible list: slot i's depth key is ~0u unless it is visible.
    const bool binned = packed_view.choices.binned;
    std::vector<uint32_t> depth_keys(binned ? packed_view.choices.num_splats : 0);
    out.visible_in_depth_order.resize(binned ? 0 : visible);
    out.entry_tiles.resize(entries);
    out.entry_splats.resize(entries);
    if (read_projected) out.projected.resize(resources_.Layout().num_splats);
    SubmitAndWait(context_, pool_, [&](VkCommandBuffer cmd) {
        RecordCopy(context_, cmd, resources_.ViewResources().splat_indices,
                   VkDeviceSize(out.visible_in_depth_order.size()) * 4,
                   out.visible_in_depth_order.data(), pending);
        RecordCopy(context_, cmd, resources_.ViewResources().depth_keys,
                   VkDeviceSize(depth_keys.size()) * 4, depth_keys.data(), pending);
        RecordCopy(context_, cmd, resources_.ViewResources().entry_keys, VkDeviceSize(entries) * 4,
                   out.entry_tiles.data(), pending);
        RecordCopy(context_, cmd, resources_.ViewResources().entry_values,
                   VkDeviceSize(entries) * 4, out.entry_splats.data(), pending);
        if (read_projected) {
            RecordCopy(context_, cmd, resources_.ViewResources().projected,
                       out.projected.size() * sizeof(shader::GaussianProjectedSplat),
                       out.projected.data(), pending);
        }
    });
    FinishCopies(pending);
    // The list's values carry entry counts above the splat index (shader::PackListValue).
    for (uint32_t& value : out.visible_in_depth_order) {
        value = shader::ListValueSplat(value, resources_.Layout().num_splats);
    }
    if (binned) {
        // The visible slots are the GPU's; their order here is the host's sort of the GPU's
        // depth keys (the bins order each tile's entries, which the tests compare).
        std::vector<std::pair<uint32_t, uint32_t>> keyed;
        for (uint32_t i = 0; i < depth_keys.size(); ++i) {
            if (depth_keys[i] != 0xFFFFFFFFu) keyed.emplace_back(depth_keys[i], i);
        }
        std::sort(keyed.begin(), keyed.end());
        for (const auto& [key, slot] : keyed) out.visible_in_depth_order.push_back(slot);
    }
    return out;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
