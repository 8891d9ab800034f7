// The Vulkan backend's submission path: both stages of one or many views in one command
// buffer per frame slot (recorded in GaussianSplatVulkanBackendSlots.cpp), submitted again with new
// cameras, frames in flight, the batch API and the readback into images. Layout and reasons:
// docs/vulkan.md "Submission path"; per-frame host costs before and after: docs/perf/.
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

// Copies `jobs` in 4 MB blocks on all cores: one thread copies a 33 MB 1080p RGBA32F image
// (and faults its fresh pages in) at a few GB/s.
struct CopyJob {
    uint8_t* destination;
    const uint8_t* source;
    int64_t bytes;
};
void ParallelCopy(const std::vector<CopyJob>& jobs) {
    constexpr int64_t kBlock = int64_t(4) << 20;
    std::vector<std::pair<size_t, int64_t>> blocks;  // (job, offset)
    for (size_t j = 0; j < jobs.size(); ++j) {
        for (int64_t at = 0; at < jobs[j].bytes; at += kBlock) blocks.push_back({j, at});
    }
    core::ParallelFor(
        static_cast<int64_t>(blocks.size()),
        [&](int64_t b) {
            const CopyJob& job = jobs[blocks[b].first];
            const int64_t at = blocks[b].second;
            std::memcpy(job.destination + at, job.source + at,
                        static_cast<size_t>(std::min(kBlock, job.bytes - at)));
        },
        /*min_chunk=*/2);
}

// An image at `offset` of a readback buffer, allocated without the zero fill (Tensor::Empty:
// at 800x800 RGBA32F the fill cost as much as the copy); ParallelCopy of `jobs` fills it.
t::geometry::Image ImageFrom(const Buffer& buffer, VkDeviceSize offset, int64_t h, int64_t w,
                             int64_t channels, core::Dtype dtype, std::vector<CopyJob>& jobs) {
    core::Tensor data = core::Tensor::Empty({h, w, channels}, dtype);
    jobs.push_back({static_cast<uint8_t*>(data.RawData()),
                    static_cast<const uint8_t*>(buffer.GetMapped()) + offset, data.NumBytes()});
    return t::geometry::Image(std::move(data));
}

}  // namespace

void GaussianSplatVulkanBackend::SubmitSlot(FrameSlot& slot) {
    if (!slot.fence) {
        slot.fence = CreateFence(*context_);
    } else {
        ResetFence(*context_, slot.fence.Get());
    }
    const bool read_back = slot.recorded.options.read_back;
    // Taken here, after any reallocation of the slot's buffers (a capacity growth
    // re-prepares the slot and replaces host_color).
    const bool imported = slot.recorded.color_imported;
    const VkBuffer color_target = imported ? slot.imported_target : slot.host_color.Get();
    const VkDeviceSize color_offset = imported ? slot.imported_target_offset : 0;
    if (read_back && (slot.copied_color_target != color_target ||
                      slot.copied_color_target_offset != color_offset)) {
        RecordReadback(slot, color_target, color_offset);
    }
    if (UsesTransfer(slot)) {
        SubmitToQueue(context_->GetQueue(), slot.cmd.Get(), VK_NULL_HANDLE, VK_NULL_HANDLE,
                      VK_PIPELINE_STAGE_2_NONE, slot.rendered.Get());
        SubmitToQueue(context_->GetTransferQueue(), slot.copy_cmd.Get(), slot.fence.Get(),
                      slot.rendered.Get(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_NULL_HANDLE);
    } else if (read_back) {
        // Two submissions to one queue: the fence of the second covers both.
        SubmitToQueue(context_->GetQueue(), slot.cmd.Get(), VK_NULL_HANDLE, VK_NULL_HANDLE,
                      VK_PIPELINE_STAGE_2_NONE, VK_NULL_HANDLE);
        SubmitToQueue(context_->GetQueue(), slot.copy_cmd.Get(), slot.fence.Get(), VK_NULL_HANDLE,
                      VK_PIPELINE_STAGE_2_NONE, VK_NULL_HANDLE);
    } else {
        Submit(*context_, slot.cmd.Get(), slot.fence.Get());
    }
    slot.serial = next_serial_++;
    slot.in_flight = true;
    ++counters_.submissions;
}

uint64_t GaussianSplatVulkanBackend::SubmitBatch(const std::vector<camera::PinholeCamera>& cameras,
                                                 const RenderConfig& requested,
                                                 const BatchOptions& options) {
    if (!cloud_) core::ThrowError("Vulkan backend: SubmitBatch before SetScene");
    if (cameras.empty()) core::ThrowError("Vulkan backend: SubmitBatch of no camera");
    CheckBatchCameras(cameras);
    for (const camera::PinholeCamera& camera : cameras) camera.Validate();
    requested.Validate();
    const RenderConfig config = WithLodTarget(requested);
    const uint32_t w = static_cast<uint32_t>(cameras[0].width);
    const uint32_t h = static_cast<uint32_t>(cameras[0].height);
    const uint32_t max_views = MaxViewsPerSubmission(w, h, options);
    if (cameras.size() > max_views) {
        core::ThrowError(
            "Vulkan backend: {} views of {}x{} exceed one submission ({} under the batch "
            "budget of {} bytes); RenderBatch splits them",
            cameras.size(), w, h, max_views, batch_budget_);
    }
    const auto start = std::chrono::steady_clock::now();
    EnsureScenePrecision(config);
    FrameSlot& slot = AcquireSlot();
    ReleaseUnusedImports();
    const uint32_t n = static_cast<uint32_t>(geometry_stage_resources_.Layout().num_splats);
    // A slot keeps the capacity it grew to for this scene.
    const uint32_t capacity =
        slot.view && slot.view.NumSplats() == n
            ? slot.view.EntryCapacity()
            : static_cast<uint32_t>(std::min<uint64_t>(MaxEntryCapacity(config, SortMaxCount()),
                                                       initial_entry_capacity_));
    FrameRecordingKey key = MakeKey(cameras, config, options, capacity);
    const VkDeviceSize color_bytes = VkDeviceSize(w) * h * ColorBytesPerPixel(options);
    uint8_t* const destination =
        options.read_back ? BatchColorDestination(options, cameras.size(), color_bytes) : nullptr;
    HostImport* import = destination != nullptr && options.color_memory
                             ? ImportHostMemory(options.color_memory)
                             : nullptr;
    key.color_imported = import != nullptr;
    const VkDeviceSize import_offset =
        import != nullptr ? VkDeviceSize(destination - options.color_memory.Data()) : 0;
    // RGBA32F colours are composited straight into the imported memory where every view's
    // offset suits a storage buffer: no copy, and the device's copy engine does not compete
    // with the compute work (on an H200 the two slowed each other down so much that a batch
    // took about as long as rendering and then copying it). The recording then names the
    // destination; UseRecording keeps one per destination (FrameSlot::spare_recordings).
    if (import != nullptr && composite_to_host_ && !options.color_uint8 &&
        composite_stage_.ColorBufferFits(w, h, import_offset) &&
        composite_stage_.ColorBufferFits(w, h, color_bytes)) {
        key.direct_color = import->buffer.Get();
        key.direct_color_offset = import_offset;
    }
    PrepareSlot(slot, key);
    if (import != nullptr) {
        slot.imported_target = import->buffer.Get();
        slot.imported_target_offset = import_offset;
        import->last_serial = next_serial_;  // the serial SubmitSlot gives this submission
    }
    slot.color_destination = destination;
    auto* params = static_cast<GaussianViewParams*>(slot.params_upload.GetMapped());
    for (size_t i = 0; i < cameras.size(); ++i) {
        params[i] = geometry_stage_resources_.ViewParams(cameras[i], config, capacity).params;
    }
    const bool reuse = UseRecording(slot, key);
    slot.record_ms = core::MillisecondsSince(start);
    slot.recording_reused = reuse;
    slot.cameras = cameras;
    slot.config = config;
    slot.options = key.options;
    const auto submit_start = std::chrono::steady_clock::now();
    SubmitSlot(slot);
    slot.submit_ms = core::MillisecondsSince(submit_start);
    slot.pending = true;
    slot.ticket = slot.serial;
    return slot.ticket;
}

std::vector<RenderOutput> GaussianSplatVulkanBackend::WaitBatch(uint64_t ticket) {
    FrameSlot* found = nullptr;
    for (auto& slot : slots_) {
        if (slot->pending && slot->ticket == ticket) found = slot.get();
    }
    if (found == nullptr)
        core::ThrowError("Vulkan backend: no pending batch has ticket {}", ticket);
    FrameSlot& slot = *found;
    const auto wait_start = std::chrono::steady_clock::now();
    WaitSlot(slot);
    double wait_ms = core::MillisecondsSince(wait_start);
    const size_t views = slot.cameras.size();
    const auto counters_of = [&](size_t i) {
        GaussianGeometryStageCounters c{};
        std::memcpy(&c,
                    static_cast<const uint8_t*>(slot.counters_readback.GetMapped()) + i * sizeof(c),
                    sizeof(c));
        return c;
    };
    BatchStats stats;
    stats.submissions = 1;
    stats.recording_reused = slot.recording_reused;

    // The allocation, not the config, cut a view short: grow the entry buffers to what the
    // largest view asked for (plus a quarter) and render the batch again, once (the geometry
    // stage reports the full request).
    const uint64_t limit = MaxEntryCapacity(slot.config, SortMaxCount());
    uint64_t asked = 0;
    for (size_t i = 0; i < views; ++i) {
        const GaussianGeometryStageCounters c = counters_of(i);
        if (c.error_flags & kCountsClamped) asked = std::max<uint64_t>(asked, c.requested_entries);
    }
    if (asked > 0 && slot.view.EntryCapacity() < limit) {
        const auto start = std::chrono::steady_clock::now();
        const uint32_t capacity =
            static_cast<uint32_t>(std::min<uint64_t>(limit, asked + asked / 4));
        slot.view.Allocate(*context_, slot.view.NumSplats(), capacity, slot.view.LodInner());
        ForgetRecordings(slot);
        FrameRecordingKey key = MakeKey(slot.cameras, slot.config, slot.options, capacity);
        key.color_imported = slot.recorded.color_imported;
        key.direct_color = slot.recorded.direct_color;
        key.direct_color_offset = slot.recorded.direct_color_offset;
        PrepareSlot(slot, key);
        auto* params = static_cast<GaussianViewParams*>(slot.params_upload.GetMapped());
        for (size_t i = 0; i < views; ++i) {
            params[i] =
                geometry_stage_resources_.ViewParams(slot.cameras[i], slot.config, capacity).params;
        }
        RecordSlot(slot, key);
        SubmitSlot(slot);
        slot.record_ms += core::MillisecondsSince(start);
        const auto again = std::chrono::steady_clock::now();
        WaitSlot(slot);
        wait_ms += core::MillisecondsSince(again);
        ++counters_.capacity_growths;
        stats.submissions = 2;
    }

    const auto readback_start = std::chrono::steady_clock::now();
    const int64_t h = slot.height, w = slot.width;
    const VkDeviceSize pixels = VkDeviceSize(w) * h;
    const VkDeviceSize color_bytes = pixels * ColorBytesPerPixel(slot.options);
    std::vector<RenderOutput> outputs(views);
    uint32_t flags = 0;
    for (size_t i = 0; i < views; ++i) {
        const GaussianGeometryStageCounters c = counters_of(i);
        RenderStats& s = outputs[i].stats;
        FillCounterStats(c, s);
        flags |= c.error_flags;
    }
    if (slot.options.read_back) {
        std::vector<CopyJob> jobs;
        for (size_t i = 0; i < views; ++i) {
            RenderOutput& out = outputs[i];
            if (slot.recorded.color_imported) {
                // The device copied the colours into the caller's memory: nothing to do.
            } else if (slot.color_destination != nullptr) {
                // The caller's memory; this submission's first view is already there.
                jobs.push_back(
                    {slot.color_destination + i * color_bytes,
                     static_cast<const uint8_t*>(slot.host_color.GetMapped()) + i * color_bytes,
                     static_cast<int64_t>(color_bytes)});
            } else {
                out.color = ImageFrom(
                    slot.host_color, i * color_bytes, h, w, 4,
                    slot.options.color_uint8 ? core::Dtype::UInt8 : core::Dtype::Float32, jobs);
            }
            if (slot.host_depth) {
                out.depth_expected =
                    ImageFrom(slot.host_depth, i * pixels * 4, h, w, 1, core::Dtype::Float32, jobs);
            }
            if (slot.host_median) {
                out.depth_median = ImageFrom(slot.host_median, i * pixels * 4, h, w, 1,
                                             core::Dtype::Float32, jobs);
            }
        }
        ParallelCopy(jobs);
    }
    WarnNewFlags(flags);
    const std::vector<double> job_ms = slot.job_timestamps.ReadMilliseconds();
    stats.gpu_ms = job_ms[0];
    if (views == 1) {
        const std::vector<double> ms = slot.pass_timestamps.ReadMilliseconds();
        const auto at = [&](TimedPass pass) {
            return std::max(0.0, ms[static_cast<uint32_t>(pass)]);
        };
        RenderStats& s = outputs[0].stats;
        s.gpu_project_ms = at(TimedPass::kProject);
        s.gpu_sort_ms = at(TimedPass::kSort);
        s.gpu_depth_sort_ms = at(TimedPass::kDepthSort);
        s.gpu_scan_emit_ms = at(TimedPass::kScanEmit);
        s.gpu_tile_sort_ms = at(TimedPass::kTileSort);
        s.gpu_lod_cut_ms = geometry_stage_resources_.HasLod() ? at(TimedPass::kLodCut) : 0.0;
        s.gpu_lod_list_ms = geometry_stage_resources_.HasLod() ? at(TimedPass::kLodCutList) : 0.0;
        s.gpu_composite_ms = at(TimedPass::kComposite);
    }
    // lod_target_ms steers by the passes' time, as on the stage path: the job's also holds
    // the copies to host memory (an RGBA32F 1080p image alone took ~1 ms of an H100's job
    // against 0.29 ms of passes, and the budget fell to one node). Batches have per-job
    // times only: the job per view.
    ObserveLodFrame(slot.config, views == 1 ? outputs[0].stats.gpu_project_ms +
                                                  outputs[0].stats.gpu_sort_ms +
                                                  outputs[0].stats.gpu_composite_ms
                                            : stats.gpu_ms / views);
    const double readback_ms = core::MillisecondsSince(readback_start);
    for (RenderOutput& out : outputs) {
        RenderStats& s = out.stats;
        s.host_record_ms = slot.recording_reused ? 0.0 : slot.record_ms / views;
        s.dispatches = slot.recorded_counts.dispatches / static_cast<int>(views);
        s.dependent_dispatches =
            slot.recorded_counts.dependent_dispatches / static_cast<int>(views);
        s.host_submit_ms = slot.submit_ms / views;
        s.host_wait_ms = wait_ms / views;
        s.host_readback_ms = readback_ms / views;
        s.geometry_ms = slot.record_ms / views;
        s.composite_ms = (wait_ms + readback_ms) / views;
    }
    slot.pending = false;
    slot.cameras.clear();
    slot.color_destination = nullptr;
    last_batch_ = stats;
    return outputs;
}

RenderOutput GaussianSplatVulkanBackend::Render(const camera::PinholeCamera& camera,
                                                const RenderConfig& config,
                                                const CompositeInputs& inputs) {
    // Scene depth and the ID image are composited on the stage path only.
    if ((inputs.scene_depth != nullptr && !inputs.scene_depth->IsEmpty()) || inputs.splat_id) {
        return GaussianSplatBackend::Render(camera, config, inputs);
    }
    BatchOptions options;
    options.read_back = inputs.read_back;
    options.expected_depth = inputs.expected_depth;
    options.median_depth = inputs.median_depth;
    std::vector<RenderOutput> outputs = WaitBatch(SubmitBatch({camera}, config, options));
    return std::move(outputs[0]);
}

std::vector<RenderOutput> GaussianSplatVulkanBackend::RenderBatch(
    const std::vector<camera::PinholeCamera>& cameras, const RenderConfig& config,
    const BatchOptions& options) {
    CheckBatchCameras(cameras);
    std::vector<RenderOutput> outputs;
    if (cameras.empty()) return outputs;
    outputs.reserve(cameras.size());
    // Several submissions, so one is copied out while the GPU renders the next (one
    // submission of all views leaves the GPU idle during the copies and the host idle during
    // the rendering): four for eight views or more, eight for sixteen or more. The first
    // part's rendering and the last one's copy overlap nothing, which smaller parts shorten,
    // but each part costs host work: 64 RGBA32F 800x800 views copied into imported memory
    // on an H200 reached 1,976 views/s in four parts, 1,988-2,001 in eight and 1,957-1,959 in
    // sixteen (docs/perf/h200.md; composited straight into it, eight parts: 2,185-2,187; other
    // part counts were not measured that way). Parts are of one size: a slot's recording and
    // per-view buffers are for one view count, so a smaller first part (tried: 2 + 7 x 8 + 6 views)
    // re-recorded and re-allocated at every submission, 1,451-1,602 views/s.
    const uint32_t fit = MaxViewsPerSubmission(static_cast<uint32_t>(cameras[0].width),
                                               static_cast<uint32_t>(cameras[0].height), options);
    const size_t parts = cameras.size() >= 16 ? 8 : cameras.size() >= 8 ? 4 : 1;
    const uint32_t chunk =
        std::min<uint32_t>(fit, static_cast<uint32_t>((cameras.size() + parts - 1) / parts));
    const uint64_t view_bytes =
        uint64_t(cameras[0].width) * cameras[0].height * ColorBytesPerPixel(options);
    uint8_t* const destination =
        options.read_back ? BatchColorDestination(options, cameras.size(), view_bytes) : nullptr;
    // Submit up to one chunk per free slot ahead, collect in order.
    std::vector<uint64_t> tickets;
    size_t next = 0, collected = 0;
    double gpu_ms = 0.0;
    int submissions = 0;
    while (collected < cameras.size()) {
        while (next < cameras.size() && tickets.size() < slots_.size()) {
            const size_t end = std::min(cameras.size(), next + chunk);
            BatchOptions part = options;  // the destination of this submission's first view
            if (destination != nullptr) part.color_destination = destination + next * view_bytes;
            tickets.push_back(SubmitBatch(
                std::vector<camera::PinholeCamera>(cameras.begin() + next, cameras.begin() + end),
                config, part));
            next = end;
        }
        std::vector<RenderOutput> part = WaitBatch(tickets.front());
        tickets.erase(tickets.begin());
        gpu_ms += std::max(0.0, last_batch_.gpu_ms);
        submissions += last_batch_.submissions;
        collected += part.size();
        for (RenderOutput& out : part) outputs.push_back(std::move(out));
    }
    last_batch_.gpu_ms = gpu_ms;
    last_batch_.submissions = submissions;
    return outputs;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
