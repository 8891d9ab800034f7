#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianGeometryStageRunner.h"
#include "open3d/core/Timer.h"

#include <chrono>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
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
                                                         uint32_t entry_capacity)
    : context_(context), pool_(context), geometry_stage_(context) {
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
    const GeometryStageViewBuffers view = resources_.View();

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
    out.visible_in_depth_order.resize(visible);
    out.entry_tiles.resize(entries);
    out.entry_splats.resize(entries);
    if (read_projected) out.projected.resize(resources_.Layout().num_splats);
    SubmitAndWait(context_, pool_, [&](VkCommandBuffer cmd) {
        RecordCopy(context_, cmd, resources_.ViewResources().splat_indices,
                   VkDeviceSize(visible) * 4, out.visible_in_depth_order.data(), pending);
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
    return out;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
