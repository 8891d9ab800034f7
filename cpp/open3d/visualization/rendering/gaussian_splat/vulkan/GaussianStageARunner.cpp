#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianStageARunner.h"

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

constexpr VkBufferUsageFlags kTransfer =
    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

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
               : "Stage A counts were clamped to the allocated tile-entry capacity";
}

}  // namespace

RenderStats StageAReadback::ToStats() const {
    RenderStats stats;
    stats.num_splats = num_splats;
    stats.num_visible = counters.visible_count;
    stats.num_tile_entries = counters.entry_count;
    stats.error_flags = counters.error_flags;
    stats.geometry_ms = stage_a_ms;
    return stats;
}

GaussianStageARunner::GaussianStageARunner(const VulkanContext& context,
                                           const PackedGaussianSplats& packed,
                                           uint32_t entry_capacity)
    : context_(context), pool_(context), stage_a_(context), entry_capacity_(entry_capacity) {
    layout_.precision = packed.precision;
    layout_.num_splats = packed.num_splats;
    layout_.sh_degree = packed.sh_degree;
    layout_.shape_words_per_splat = packed.shape_words_per_splat;
    layout_.sh_words_per_splat = packed.sh_words_per_splat;
    layout_.center_min = packed.center_min;
    layout_.center_max = packed.center_max;
    const uint32_t n = static_cast<uint32_t>(packed.num_splats);

    positions_ = UploadBuffer(packed.positions.data(), packed.positions.size() * sizeof(float));
    shape_ = UploadBuffer(packed.shape.data(), packed.shape.size() * 4);
    // Degree 0: nothing is read from the SH binding, but it must name a buffer.
    const uint32_t placeholder[4] = {0, 0, 0, 0};
    sh_ = packed.sh.empty() ? UploadBuffer(placeholder, sizeof(placeholder))
                            : UploadBuffer(packed.sh.data(), packed.sh.size() * 4);
    visibility_ = UploadBuffer(packed.visibility.data(), packed.visibility.size() * 4);
    scene_bytes_ = (packed.positions.size() + packed.shape.size() + packed.sh.size() +
                    packed.visibility.size()) *
                   4;

    const StageAStorageRequirements need =
        GaussianStageA::GetStorageRequirements(n, entry_capacity);
    const auto make = [&](VkDeviceSize bytes, VkBufferUsageFlags usage) {
        return Buffer(context, bytes, usage | kTransfer, MemoryUsage::kDevice);
    };
    view_params_ = make(need.view_params_bytes, need.view_params_usage);
    projected_ = make(need.projected_bytes, need.usage);
    counters_ = make(need.counters_bytes, need.counters_usage);
    depth_keys_ = make(need.depth_keys_bytes, need.usage);
    splat_indices_ = make(need.splat_indices_bytes, need.usage);
    scan_ = make(need.scan_bytes, need.usage);
    entry_keys_ = make(need.entry_keys_bytes, need.usage);
    entry_values_ = make(need.entry_values_bytes, need.usage);
    keys_alt_ = make(need.sort.keys_alt_bytes, need.sort.scratch_usage);
    values_alt_ = make(need.sort.values_alt_bytes, need.sort.scratch_usage);
    histogram_ = make(need.sort.histogram_bytes, need.sort.scratch_usage);
    sort_params_ = make(need.sort.params_bytes, need.sort.params_usage);
}

Buffer GaussianStageARunner::UploadBuffer(const void* data, VkDeviceSize bytes) {
    const VkDeviceSize size = std::max<VkDeviceSize>(bytes, 16);
    Buffer device(context_, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | kTransfer,
                  MemoryUsage::kDevice);
    Buffer staging(context_, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::kHostUpload);
    std::memset(staging.GetMapped(), 0, size);
    if (bytes > 0) std::memcpy(staging.GetMapped(), data, bytes);
    SubmitAndWait(context_, pool_, [&](VkCommandBuffer cmd) {
        const VkBufferCopy region{0, 0, size};
        vkCmdCopyBuffer(cmd, staging.Get(), device.Get(), 1, &region);
    });
    return device;
}

void GaussianStageARunner::SetVisibility(const std::vector<uint32_t>& mask) {
    if (mask.size() * 4 > visibility_.GetSize()) {
        core::ThrowError("GaussianStageARunner: visibility mask of {} words, the scene has {}",
                         mask.size(), visibility_.GetSize() / 4);
    }
    visibility_ = UploadBuffer(mask.data(), mask.size() * 4);
}

StageAReadback GaussianStageARunner::Run(const camera::PinholeCamera& camera,
                                         const RenderConfig& config, bool read_projected) {
    ViewPackingInputs inputs;
    inputs.num_splats = layout_.num_splats;
    inputs.packed_sh_degree = layout_.sh_degree;
    inputs.precision = layout_.precision;
    inputs.sh_words_per_splat = layout_.sh_words_per_splat;
    inputs.entry_capacity = entry_capacity_;
    inputs.center_min = layout_.center_min;
    inputs.center_max = layout_.center_max;
    const shader::GaussianViewParams params = PackGaussianViewParams(camera, config, inputs);

    StageASceneBuffers scene;
    scene.positions = positions_.Range();
    scene.shape = shape_.Range();
    scene.sh = sh_.Range();
    scene.visibility = visibility_.Range();
    scene.num_splats = static_cast<uint32_t>(layout_.num_splats);
    scene.packed_sh_degree = layout_.sh_degree;
    scene.sh_words_per_splat = layout_.sh_words_per_splat;
    scene.precision = layout_.precision;
    StageAViewBuffers view;
    view.view_params = view_params_.Range();
    view.projected = projected_.Range();
    view.counters = counters_.Range();
    view.depth_keys = depth_keys_.Range();
    view.splat_indices = splat_indices_.Range();
    view.scan = scan_.Range();
    view.entry_keys = entry_keys_.Range();
    view.entry_values = entry_values_.Range();
    view.sort_scratch = {keys_alt_.Range(), values_alt_.Range(), histogram_.Range(),
                         sort_params_.Range()};

    StageAReadback out;
    out.num_splats = layout_.num_splats;
    std::vector<PendingCopy> pending;
    {
        CommandBuffer cmd = pool_.Allocate();
        cmd.Begin();
        stage_a_.Record(cmd.Get(), scene, view, params);
        ComputeToTransferBarrier(cmd.Get());
        RecordCopy(context_, cmd.Get(), counters_, sizeof(out.counters), &out.counters, pending);
        cmd.End();
        UniqueFence fence = CreateFence(context_);
        const auto start = std::chrono::steady_clock::now();
        Submit(context_, cmd.Get(), fence.Get());
        Wait(context_, fence.Get());
        out.stage_a_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        FinishCopies(pending);
    }

    // Error flags are read after the fence and reported once per view (this runner).
    const uint32_t new_flags = out.counters.error_flags & ~warned_flags_;
    for (uint32_t bit : {kEntriesDropped, kCountsClamped}) {
        if (new_flags & bit)
            core::LogWarning("Gaussian splat Stage A (Vulkan): {}", FlagMessage(bit));
    }
    warned_flags_ |= out.counters.error_flags;

    // Second copy with the sizes now known: only the live part of each buffer.
    const uint32_t visible = out.counters.visible_count;
    const uint32_t entries = out.counters.entry_count;
    out.visible_in_depth_order.resize(visible);
    out.entry_tiles.resize(entries);
    out.entry_splats.resize(entries);
    if (read_projected) out.projected.resize(layout_.num_splats);
    SubmitAndWait(context_, pool_, [&](VkCommandBuffer cmd) {
        RecordCopy(context_, cmd, splat_indices_, VkDeviceSize(visible) * 4,
                   out.visible_in_depth_order.data(), pending);
        RecordCopy(context_, cmd, entry_keys_, VkDeviceSize(entries) * 4, out.entry_tiles.data(),
                   pending);
        RecordCopy(context_, cmd, entry_values_, VkDeviceSize(entries) * 4, out.entry_splats.data(),
                   pending);
        if (read_projected) {
            RecordCopy(context_, cmd, projected_,
                       out.projected.size() * sizeof(shader::GaussianProjectedSplat),
                       out.projected.data(), pending);
        }
    });
    FinishCopies(pending);
    return out;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
