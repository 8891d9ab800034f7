// The Vulkan backend's frame slots for the submission path: how many frames fly, the
// per-slot buffers and host imports, and each slot's command buffer recorded once per
// (scene, config, size, outputs) key. Submitting and reading back:
// GaussianSplatVulkanBackendFrames.cpp; docs/vulkan.md "Submission path".
#include <algorithm>
#include <chrono>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Timer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

using shader::GaussianGeometryStageCounters;
using shader::GaussianViewParams;

constexpr int kMaxFramesInFlight = 4;
// Spare recordings a slot keeps (FrameSlot::spare_recordings): RenderBatch's eight parts over
// two slots give each slot at most eight destinations.
constexpr size_t kMaxSpareRecordings = 8;
constexpr VkBufferUsageFlags kTransfer =
    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

bool SameChoices(const GeometryStageChoices& a, const GeometryStageChoices& b) {
    return a.num_splats == b.num_splats && a.sh_degree == b.sh_degree &&
           a.antialias == b.antialias && a.packed_key == b.packed_key && a.binned == b.binned &&
           a.tile_bits == b.tile_bits && a.num_tiles == b.num_tiles &&
           a.entry_capacity == b.entry_capacity &&
           a.entry_capacity_allocated == b.entry_capacity_allocated &&
           a.lod_cut_search == b.lod_cut_search;
}

bool SameOptions(const BatchOptions& a, const BatchOptions& b) {
    return a.read_back == b.read_back && a.color_uint8 == b.color_uint8 &&
           a.expected_depth == b.expected_depth && a.median_depth == b.median_depth;
}

// Device bytes of one view's images in the per-view buffers.
VkDeviceSize ViewBytes(uint32_t width, uint32_t height, const BatchOptions& options) {
    const VkDeviceSize pixels = VkDeviceSize(width) * height;
    return pixels * (ColorBytesPerPixel(options) + (options.expected_depth ? 4 : 0) +
                     (options.median_depth ? 4 : 0));
}

// Everything earlier in the queue (the previous view's copies and composite, the previous
// submission of this slot, scene uploads) before what follows reads or writes.
void FullBarrier(VkCommandBuffer cmd) {
    RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                        VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                        VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                        VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
}

}  // namespace

bool FrameRecordingKey::operator==(const FrameRecordingKey& other) const {
    return views == other.views && width == other.width && height == other.height &&
           entry_capacity == other.entry_capacity && scene_serial == other.scene_serial &&
           SameChoices(choices, other.choices) && SameGeometryConfig(config, other.config) &&
           config.background == other.config.background && SameOptions(options, other.options) &&
           color_imported == other.color_imported && direct_color == other.direct_color &&
           direct_color_offset == other.direct_color_offset;
}

void GaussianSplatVulkanBackend::SetFramesInFlight(int count) {
    if (count < 1 || count > kMaxFramesInFlight) {
        core::ThrowError("Vulkan backend: frames in flight must be 1..{}, not {}",
                         kMaxFramesInFlight, count);
    }
    WaitAllSlots();
    slots_.clear();
    for (int i = 0; i < count; ++i) slots_.push_back(std::make_unique<FrameSlot>(*context_));
}

void GaussianSplatVulkanBackend::SetBatchBudget(uint64_t bytes) {
    if (bytes == 0) core::ThrowError("Vulkan backend: the batch budget must be > 0 bytes");
    batch_budget_ = bytes;
}

uint32_t GaussianSplatVulkanBackend::MaxViewsPerSubmission(uint32_t width, uint32_t height,
                                                           const BatchOptions& options) const {
    const VkDeviceSize per_view = std::max<VkDeviceSize>(1, ViewBytes(width, height, options));
    return static_cast<uint32_t>(std::clamp<uint64_t>(batch_budget_ / per_view, 1, 4096));
}

bool GaussianSplatVulkanBackend::AnySlotBusy() const {
    return std::any_of(slots_.begin(), slots_.end(),
                       [](const auto& slot) { return slot->in_flight; });
}

void GaussianSplatVulkanBackend::WaitSlot(FrameSlot& slot) {
    if (!slot.in_flight) return;
    Wait(*context_, slot.fence.Get());
    slot.in_flight = false;
    // One queue runs submissions in order: everything up to this one has completed.
    completed_serial_ = std::max(completed_serial_, slot.serial);
    deferred_.Release(completed_serial_);
}

void GaussianSplatVulkanBackend::WaitAllSlots() {
    for (auto& slot : slots_) WaitSlot(*slot);
    deferred_.Clear();
}

void GaussianSplatVulkanBackend::RetireSceneBuffers(bool visibility_only) {
    if (!AnySlotBusy()) return;
    // Frames in flight still read the scene: keep its buffers until they complete.
    const uint64_t last = next_serial_ - 1;
    deferred_.Defer(last, std::move(geometry_stage_resources_.visibility));
    ++counters_.deferred_releases;
    if (visibility_only) return;
    for (Buffer* buffer : {&geometry_stage_resources_.positions, &geometry_stage_resources_.shape,
                           &geometry_stage_resources_.sh}) {
        deferred_.Defer(last, std::move(*buffer));
        ++counters_.deferred_releases;
    }
}

void GaussianSplatVulkanBackend::RetireLod() {
    if (geometry_stage_resources_.lod_nodes && AnySlotBusy()) {
        deferred_.Defer(next_serial_ - 1, std::move(geometry_stage_resources_.lod_nodes));
        ++counters_.deferred_releases;
    }
    geometry_stage_resources_.ClearLod();
}

void GaussianSplatVulkanBackend::EnsureScenePrecision(const RenderConfig& config) {
    const SplatPrecision precision = SplatPrecisionFor(config.compact_storage);
    if (precision == geometry_stage_resources_.Layout().precision) return;
    if (pool_scene_) {
        core::ThrowError(
            "Vulkan backend: a streamed scene pool keeps the precision it was made at ({}); a "
            "frame with RenderConfig::compact_storage = {} cannot draw it "
            "(SplatStreamOptions::compact_storage chooses the pool's)",
            precision == SplatPrecision::kCompact ? "float32" : "half precision",
            precision == SplatPrecision::kCompact ? "true" : "false");
    }
    WaitForStageWork();
    geometry_.in_flight = false;
    UploadScene(precision);
    geometry_.valid = false;
}

void GaussianSplatVulkanBackend::ReleaseUnusedImports() {
    // Ours is the only reference left and nothing in flight writes it: let it go (the
    // memory is freed with it).
    std::erase_if(host_imports_, [&](const std::unique_ptr<HostImport>& import) {
        const bool unused =
            import->memory.UseCount() == 1 && import->last_serial <= completed_serial_;
        if (!unused) return false;
        ++counters_.host_import_releases;
        // A recording or readback copy that writes it must not be reused, even by a later
        // import that gets the same handle (lavapipe reuses handles).
        for (auto& slot : slots_) {
            if (slot->recorded.direct_color == import->buffer.Get()) ForgetRecordings(*slot);
            std::erase_if(slot->spare_recordings, [&](const FrameSlot::SpareRecording& spare) {
                return spare.key.direct_color == import->buffer.Get();
            });
            if (slot->copied_color_target == import->buffer.Get()) {
                slot->copied_color_target = VK_NULL_HANDLE;
            }
        }
        return true;
    });
}

GaussianSplatVulkanBackend::HostImport* GaussianSplatVulkanBackend::ImportHostMemory(
    const BatchHostMemory& memory) {
    for (auto& import : host_imports_) {
        if (import->memory.SameMemory(memory)) return import.get();
    }
    const uint64_t alignment = context_->GetHostImportAlignment();
    if (!context_->CanImportHostMemory() || host_import_failed_ || alignment == 0 ||
        reinterpret_cast<uintptr_t>(memory.Data()) % alignment != 0 ||
        memory.Size() % alignment != 0) {
        return nullptr;
    }
    auto import = std::make_unique<HostImport>();
    try {
        import->buffer = Buffer::ImportHost(
            *context_, memory.Data(), memory.Size(),
            VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
            /*shared_with_transfer=*/true);
    } catch (const core::Open3DError& error) {
        core::LogWarning("Vulkan backend: {}; batch colours are copied on the host instead",
                         error.what());
        host_import_failed_ = true;
        return nullptr;
    }
    import->memory = memory;
    ++counters_.host_imports;
    host_imports_.push_back(std::move(import));
    return host_imports_.back().get();
}

FrameSlot& GaussianSplatVulkanBackend::AcquireSlot() {
    // The slot whose last submission is oldest: with frames in flight it is usually done.
    FrameSlot* best = nullptr;
    for (auto& slot : slots_) {
        if (slot->pending) continue;
        if (best == nullptr || slot->serial < best->serial) best = slot.get();
    }
    if (best == nullptr) {
        core::ThrowError(
            "Vulkan backend: all {} frame slots hold batches not collected yet: call WaitBatch "
            "before submitting more",
            slots_.size());
    }
    WaitSlot(*best);
    return *best;
}

FrameRecordingKey GaussianSplatVulkanBackend::MakeKey(
    const std::vector<camera::PinholeCamera>& cameras, const RenderConfig& config,
    const BatchOptions& options, uint32_t entry_capacity) const {
    FrameRecordingKey key;
    key.views = static_cast<uint32_t>(cameras.size());
    key.width = static_cast<uint32_t>(cameras[0].width);
    key.height = static_cast<uint32_t>(cameras[0].height);
    key.entry_capacity = entry_capacity;
    key.scene_serial = scene_serial_;
    key.choices = geometry_stage_resources_.ViewParams(cameras[0], config, entry_capacity).choices;
    key.config = config;
    key.options = options;
    // The destination is the readback copy's business (re-recorded alone when it changes),
    // and a key must not keep the caller's memory alive.
    key.options.color_destination = nullptr;
    key.options.color_memory = BatchHostMemory();
    return key;
}

void GaussianSplatVulkanBackend::PrepareSlot(FrameSlot& slot, const FrameRecordingKey& key) {
    const VulkanContext& context = *context_;
    const uint32_t n = static_cast<uint32_t>(geometry_stage_resources_.Layout().num_splats);
    const std::optional<uint32_t> lod_inner = geometry_stage_resources_.LodInner();
    if (!slot.view || slot.view.NumSplats() != n ||
        slot.view.EntryCapacity() != key.entry_capacity || slot.view.LodInner() != lod_inner) {
        slot.view.Allocate(context, n, key.entry_capacity, lod_inner);
        ForgetRecordings(slot);
    }
    const CompositeColorFormat format =
        key.options.color_uint8 ? CompositeColorFormat::kRgba8 : CompositeColorFormat::kRgba32f;
    if (!slot.color || slot.width != key.width || slot.height != key.height ||
        slot.color_format != format) {
        const CompositeStageStorageRequirements need =
            GaussianCompositeStage::GetStorageRequirements();
        const VkImageUsageFlags usage = need.image_usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        slot.color = Image(context, key.width, key.height, ToVkFormat(format), usage);
        slot.depth = Image(context, key.width, key.height, need.scalar_format, usage);
        slot.alpha = Image(context, key.width, key.height, need.scalar_format, usage);
        slot.median = Image(context, key.width, key.height, need.scalar_format, usage);
        slot.composite_state =
            Buffer(context, GaussianCompositeStage::StateBytes(key.width, key.height),
                   need.state_usage, MemoryUsage::kDevice);
        slot.width = key.width;
        slot.height = key.height;
        slot.color_format = format;
        ForgetRecordings(slot);
    }
    // Per-view buffers for more views than this submission has serve it too (the last part of
    // a split batch, or a smaller batch, then re-records without re-allocating).
    const bool same_outputs =
        slot.params_upload && slot.view_capacity >= key.views && slot.has_recording &&
        slot.recorded.width == key.width && slot.recorded.height == key.height &&
        SameOptions(slot.recorded.options, key.options) &&
        slot.recorded.color_imported == key.color_imported &&
        (slot.recorded.direct_color == VK_NULL_HANDLE) == (key.direct_color == VK_NULL_HANDLE);
    if (!same_outputs) {
        const VkDeviceSize pixels = VkDeviceSize(key.width) * key.height;
        const auto per_view = [&](bool wanted, VkDeviceSize bytes, MemoryUsage memory,
                                  VkBufferUsageFlags usage = kTransfer) {
            return wanted ? Buffer(context, bytes * key.views, usage, memory,
                                   /*shared_with_transfer=*/true)
                          : Buffer();
        };
        const BatchOptions& o = key.options;
        const VkDeviceSize color_bytes = pixels * ColorBytesPerPixel(o);
        // A batch's views land in device buffers (the composite's images hold one view) and,
        // when read back, reach host memory in one linear copy per kind: on an H200 that took
        // 0.65 ms of GPU time per 800x800 RGBA32F view, copying each image straight into host
        // memory 1.13 ms. A single view without readback stays in the images, copied nowhere.
        const bool on_device = o.read_back || key.views > 1;
        // The composite writes RGBA32F colours into it (RecordSlot), or straight into the
        // caller's imported memory (then it is not needed).
        slot.device_color =
            per_view(on_device && key.direct_color == VK_NULL_HANDLE, color_bytes,
                     MemoryUsage::kDevice, kTransfer | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        slot.device_depth =
            per_view(on_device && o.expected_depth, pixels * 4, MemoryUsage::kDevice);
        slot.device_median =
            per_view(on_device && o.median_depth, pixels * 4, MemoryUsage::kDevice);
        slot.host_color =
            per_view(o.read_back && !key.color_imported, color_bytes, MemoryUsage::kHostReadback);
        slot.host_depth =
            per_view(o.read_back && o.expected_depth, pixels * 4, MemoryUsage::kHostReadback);
        slot.host_median =
            per_view(o.read_back && o.median_depth, pixels * 4, MemoryUsage::kHostReadback);
        slot.params_upload = per_view(true, sizeof(GaussianViewParams), MemoryUsage::kHostUpload);
        slot.counters_readback =
            per_view(true, sizeof(GaussianGeometryStageCounters), MemoryUsage::kHostReadback);
        slot.view_capacity = key.views;
        ForgetRecordings(slot);
    }
}

void GaussianSplatVulkanBackend::ForgetRecordings(FrameSlot& slot) {
    slot.has_recording = false;
    slot.spare_recordings.clear();
}

bool GaussianSplatVulkanBackend::UseRecording(FrameSlot& slot, const FrameRecordingKey& key) {
    if (slot.has_recording && slot.recorded == key) return true;
    auto spare = std::find_if(slot.spare_recordings.begin(), slot.spare_recordings.end(),
                              [&](const FrameSlot::SpareRecording& s) { return s.key == key; });
    if (slot.has_recording) {
        // The current recording becomes a spare (the oldest spare goes when there are many).
        if (spare == slot.spare_recordings.end() &&
            slot.spare_recordings.size() >= kMaxSpareRecordings) {
            slot.spare_recordings.erase(slot.spare_recordings.begin());
            spare = slot.spare_recordings.end();
        }
        FrameSlot::SpareRecording parked{slot.recorded, std::move(slot.cmd), slot.recorded_counts};
        if (spare != slot.spare_recordings.end()) {
            slot.cmd = std::move(spare->cmd);
            slot.recorded = spare->key;
            slot.recorded_counts = spare->counts;
            *spare = std::move(parked);
            slot.copied_color_target = VK_NULL_HANDLE;  // copy_cmd followed the other one
            return true;
        }
        slot.spare_recordings.push_back(std::move(parked));
    }
    RecordSlot(slot, key);
    return false;
}

void GaussianSplatVulkanBackend::RecordSlot(FrameSlot& slot, const FrameRecordingKey& key) {
    if (slot.cmd.Get() == VK_NULL_HANDLE) slot.cmd = pool_.Allocate();
    const VkCommandBuffer cmd = slot.cmd.Get();
    slot.cmd.Begin(/*one_time_submit=*/false);
    const CommandTally tally;
    const bool one_view = key.views == 1;
    slot.job_timestamps.RecordReset(cmd);
    if (one_view) slot.pass_timestamps.RecordReset(cmd);
    slot.job_timestamps.RecordBegin(cmd, 0u);

    const GeometryStageSceneBuffers scene = geometry_stage_resources_.Scene();
    GeometryStageViewBuffers buffers = slot.view.Buffers();
    buffers.tile_ranges = slot.composite_state.Range();
    PackedView view;  // the parameters come from params_upload; the choices pick pipelines
    view.choices = key.choices;

    CompositeParams params;
    for (int c = 0; c < 3; ++c) params.background[c] = static_cast<float>(key.config.background[c]);
    params.expected_depth = key.options.expected_depth;
    params.median_depth = key.options.median_depth;
    CompositeStageInputs inputs;
    inputs.projected = slot.view.projected.Range();
    inputs.entry_keys = slot.view.entry_keys.Range();
    inputs.entry_values = slot.view.entry_values.Range();
    inputs.entry_count = slot.view.counters.Range(
        offsetof(GaussianGeometryStageCounters, entry_count), sizeof(uint32_t));
    inputs.entry_capacity = slot.view.EntryCapacity();
    inputs.ranges_written = geometry_stage_.WritesTileRanges(key.choices);
    // Each view's composite follows its own geometry stage in this recording.
    inputs.state_zeroed = inputs.ranges_written;
    CompositeStageTargets targets;
    targets.width = key.width;
    targets.height = key.height;
    targets.color_format = slot.color_format;
    targets.color = slot.color.GetView();
    targets.depth = slot.depth.GetView();
    targets.alpha = slot.alpha.GetView();
    targets.median_depth = slot.median.GetView();

    const VkDeviceSize pixels = VkDeviceSize(key.width) * key.height;
    const VkDeviceSize color_bytes = pixels * ColorBytesPerPixel(key.options);
    // RGBA32F views bound for the device buffer are composited straight into it: the image
    // and its copy (0.18 ms per 800x800 view on an H200) are skipped. Every view's offset is
    // a multiple of the first's, so one check covers the batch.
    const bool direct = key.direct_color != VK_NULL_HANDLE;
    const bool color_into_buffer =
        direct || (slot.device_color && slot.color_format == CompositeColorFormat::kRgba32f &&
                   composite_stage_.ColorBufferFits(key.width, key.height, color_bytes));
    for (uint32_t i = 0; i < key.views; ++i) {
        FullBarrier(cmd);
        const BufferRange source =
            slot.params_upload.Range(i * sizeof(GaussianViewParams), sizeof(GaussianViewParams));
        geometry_stage_.Record(cmd, scene, buffers, view,
                               one_view ? &slot.pass_timestamps : nullptr, &source);
        // The entries and counters to the composite's reads and the counters' copy.
        RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT);
        const VkBufferCopy counters{0, i * sizeof(GaussianGeometryStageCounters),
                                    sizeof(GaussianGeometryStageCounters)};
        vkCmdCopyBuffer(cmd, slot.view.counters.Get(), slot.counters_readback.Get(), 1, &counters);
        for (const Image* image : {&slot.color, &slot.depth, &slot.alpha, &slot.median}) {
            RecordImageBarrier(cmd, image->Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                               VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                               VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                               VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
        targets.color_buffer =
            direct ? BufferRange{key.direct_color, key.direct_color_offset + i * color_bytes,
                                 color_bytes}
            : color_into_buffer ? slot.device_color.Range(i * color_bytes, color_bytes)
                                : BufferRange{};
        if (one_view) slot.pass_timestamps.RecordBegin(cmd, TimedPass::kComposite);
        composite_stage_.RecordComposite(cmd, inputs, targets, slot.composite_state.Range(),
                                         params);
        if (one_view) slot.pass_timestamps.RecordEnd(cmd, TimedPass::kComposite);
        // The composite's images to the copies into the per-view device buffers.
        const std::pair<const Image*, const Buffer*> copies[] = {
            {&slot.color, &slot.device_color},
            {&slot.depth, &slot.device_depth},
            {&slot.median, &slot.device_median}};
        for (const auto& [image, buffer] : copies) {
            if (!*buffer || (image == &slot.color && color_into_buffer)) continue;
            RecordImageBarrier(cmd, image->Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                               VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                               VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                               VK_ACCESS_2_TRANSFER_READ_BIT);
            const VkDeviceSize bytes = image == &slot.color ? color_bytes : pixels * 4;
            RecordCopyToBuffer(cmd, *image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer->Get(),
                               i * bytes);
        }
    }
    // The host reads the counters (and colours written straight to it) after the fence; the
    // other images reach it through copy_cmd.
    RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    slot.copied_color_target = VK_NULL_HANDLE;  // copy_cmd is recorded again before use
    slot.job_timestamps.RecordEnd(cmd, 0u);
    slot.cmd.End();
    slot.recorded = key;
    slot.recorded_counts = tally.Counts();
    slot.has_recording = true;
    ++counters_.recordings;
}

void GaussianSplatVulkanBackend::RecordReadback(FrameSlot& slot, VkBuffer color_target,
                                                VkDeviceSize color_offset) {
    if (slot.copy_cmd.Get() == VK_NULL_HANDLE) {
        slot.copy_cmd = UsesTransfer(slot) ? transfer_pool_->Allocate() : pool_.Allocate();
    }
    const VkCommandBuffer copy_cmd = slot.copy_cmd.Get();
    slot.copy_cmd.Begin(/*one_time_submit=*/false);
    if (!UsesTransfer(slot)) {
        // Same queue, after cmd: its per-view copies and the composite's buffer writes first.
        // (On the transfer queue the semaphore orders the copies after the rendering.)
        RecordMemoryBarrier(copy_cmd,
                            VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    }
    // The whole submission to host memory: one linear copy per kind, of the submission's views
    // (the buffers may hold more).
    const FrameRecordingKey& key = slot.recorded;
    const VkDeviceSize pixels = VkDeviceSize(key.width) * key.height * key.views;
    if (key.direct_color == VK_NULL_HANDLE) {
        const VkBufferCopy color{0, color_offset, pixels * ColorBytesPerPixel(key.options)};
        vkCmdCopyBuffer(copy_cmd, slot.device_color.Get(), color_target, 1, &color);
    }
    for (const auto& [device, host] :
         {std::pair<const Buffer*, const Buffer*>{&slot.device_depth, &slot.host_depth},
          {&slot.device_median, &slot.host_median}}) {
        if (!*host) continue;
        const VkBufferCopy region{0, 0, pixels * 4};
        vkCmdCopyBuffer(copy_cmd, device->Get(), host->Get(), 1, &region);
    }
    RecordMemoryBarrier(copy_cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    slot.copy_cmd.End();
    if (UsesTransfer(slot) && !slot.rendered) slot.rendered = CreateBinarySemaphore(*context_);
    slot.copied_color_target = color_target;
    slot.copied_color_target_offset = color_offset;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
