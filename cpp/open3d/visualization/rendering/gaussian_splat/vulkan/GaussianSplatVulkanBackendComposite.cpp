// The stage path's composite (RenderComposite): the frame a CompositeSink receives, recorded
// once per RecordingKey and submitted again while nothing it names changes, waited for at
// once or, for a sink that signals a semaphore and reads nothing back, before the next use of
// what it touches (WaitForComposite).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/Timer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

void GaussianSplatVulkanBackend::WaitForComposite() {
    if (!composite_in_flight_) return;
    Wait(*context_, composite_fence_.Get());
    const std::vector<double> ms = composite_stage_timestamps_.ReadMilliseconds();
    last_composite_gpu_ms_ = composite_in_flight_empty_ ? 0.0 : PassMs(ms, TimedPass::kComposite);
    composite_in_flight_ = false;
    if (!composite_counters_pending_) return;
    composite_counters_pending_ = false;
    // The geometry stage ran before the composite: its fence is signalled.
    WaitForGeometry();
    const shader::GaussianGeometryStageCounters counters = ReadStageCounters();
    const bool outgrew = EntriesOutgrewBuffers(counters);
    WarnNewFlags(outgrew ? counters.error_flags & ~kCountsClamped : counters.error_flags);
    const RenderStats& g = geometry_.times;
    ObserveLodFrame(geometry_.config, g.gpu_project_ms + g.gpu_sort_ms + last_composite_gpu_ms_);
    if (outgrew) {
        // The frame was handed on before its counters were known: the next one gets room.
        initial_entry_capacity_ = std::max(initial_entry_capacity_, GrownEntryCapacity(counters));
        ++counters_.capacity_growths;
        core::LogWarning(
            "Vulkan backend: a frame handed to another API asked for {} tile entries, more "
            "than the {} its buffers held, and lost the rest; the next frame has room",
            counters.requested_entries, geometry_stage_resources_.EntryCapacity());
    }
}

shader::GaussianGeometryStageCounters GaussianSplatVulkanBackend::ReadStageCounters() {
    shader::GaussianGeometryStageCounters c{};
    std::memcpy(&c, counters_readback_.GetMapped(), sizeof(c));
    last_counters_ = c;
    const uint64_t capacity = geometry_stage_resources_.EntryCapacity();
    entries_have_room_ =
        (c.error_flags & kCountsClamped) == 0 && uint64_t(c.requested_entries) * 4 <= capacity * 3;
    return c;
}

bool GaussianSplatVulkanBackend::EntriesOutgrewBuffers(
    const shader::GaussianGeometryStageCounters& counters) const {
    return (counters.error_flags & kCountsClamped) != 0 && !growing_ &&
           geometry_stage_resources_.EntryCapacity() <
               MaxEntryCapacity(geometry_.config, SortMaxCount());
}

uint32_t GaussianSplatVulkanBackend::GrownEntryCapacity(
    const shader::GaussianGeometryStageCounters& counters) const {
    const uint64_t limit = MaxEntryCapacity(geometry_.config, SortMaxCount());
    const uint64_t asked = counters.requested_entries;
    return static_cast<uint32_t>(std::min<uint64_t>(limit, asked + asked / 4));
}

RenderStats GaussianSplatVulkanBackend::RenderAgainWithGrownBuffers(
    CompositeSink& sink, const shader::GaussianGeometryStageCounters& counters) {
    EnsureViewBuffers(GrownEntryCapacity(counters));
    ++counters_.capacity_growths;
    growing_ = true;
    const camera::PinholeCamera camera = geometry_.camera;
    const RenderConfig config = geometry_.config;
    geometry_.valid = false;
    RenderGeometryStage(camera, config);
    const RenderStats stats = RenderComposite(sink);
    growing_ = false;
    return stats;
}

void GaussianSplatVulkanBackend::FillCounterStats(const shader::GaussianGeometryStageCounters& c,
                                                  RenderStats& s) const {
    const bool lod = geometry_stage_resources_.HasLod();
    s.num_splats = geometry_stage_resources_.Layout().num_splats;
    s.num_visible = c.visible_count;
    s.lod_cut_nodes = lod ? c.lod_cut_nodes : 0;
    s.lod_walk_visited = lod ? c.lod_walk_visited : 0;
    s.lod_walks = lod ? int(c.lod_walks) : 0;
    s.num_tile_entries = c.entry_count;
    s.error_flags = c.error_flags;
    s.gpu_scene_bytes = static_cast<int64_t>(geometry_stage_resources_.SceneBytes());
}

void GaussianSplatVulkanBackend::WaitForStageWork() {
    if (geometry_.in_flight) {
        SubmitHeldGeometry(VK_NULL_HANDLE);
        Wait(*context_, geometry_stage_fence_.Get());
    }
    WaitForComposite();
}

void GaussianSplatVulkanBackend::SubmitHeldGeometry(VkSemaphore wait) {
    if (!geometry_held_) return;
    geometry_held_ = false;
    SubmitToQueue(context_->GetQueue(), geometry_stage_cmd_.Get(), geometry_stage_fence_.Get(),
                  wait, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_NULL_HANDLE);
}

void GaussianSplatVulkanBackend::RecordCompositeFrame(CompositeSink& sink, VkCommandBuffer cmd,
                                                      const CompositeParams& params, bool empty) {
    const uint32_t w = static_cast<uint32_t>(geometry_.camera.width);
    const uint32_t h = static_cast<uint32_t>(geometry_.camera.height);
    const Image& color = sink.ColorTarget();
    composite_stage_timestamps_.RecordReset(cmd);
    // Geometry stage's results (an earlier submission to this queue, maybe still running) to
    // the composite's reads, and to its writes of the state buffer the tile bins wrote.
    RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT |
                            VK_PIPELINE_STAGE_2_CLEAR_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                            VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
    CompositeSink::Frame frame;
    frame.cmd = cmd;
    frame.empty = empty;
    frame.write_stage =
        empty ? VK_PIPELINE_STAGE_2_CLEAR_BIT : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    frame.write_access =
        empty ? VK_ACCESS_2_TRANSFER_WRITE_BIT : VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
    frame.depth = &depth_;
    frame.alpha = &alpha_;
    frame.median = &median_;
    frame.splat_id = params.splat_id ? &splat_id_ : nullptr;
    if (params.splat_id && !splat_id_) {
        core::ThrowError(
            "Vulkan backend: this composite's sink asks for an ID image it has none of");
    }
    frame.composite_stage = &composite_stage_;
    frame.timestamps = &composite_stage_timestamps_;
    // The last frame copied these (readback) or read them in a depth merge.
    const std::array<const Image*, 4> written{&depth_, &alpha_, &median_, frame.splat_id};
    for (const Image* image : written) {
        if (image == nullptr) continue;
        RecordImageBarrier(cmd, image->Get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                           VK_IMAGE_LAYOUT_GENERAL,
                           VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                           VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                           frame.write_stage, frame.write_access);
    }
    sink.RecordBefore(frame);
    if (empty) {
        const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        VkClearColorValue background{};
        for (int c = 0; c < 3; ++c) background.float32[c] = params.background[c];
        const VkClearColorValue zero{};
        vkCmdClearColorImage(cmd, color.Get(), VK_IMAGE_LAYOUT_GENERAL, &background, 1, &all);
        for (const Image* image : {&depth_, &alpha_, &median_}) {
            vkCmdClearColorImage(cmd, image->Get(), VK_IMAGE_LAYOUT_GENERAL, &zero, 1, &all);
        }
        if (frame.splat_id) {
            VkClearColorValue none{};
            none.uint32[0] = kNoSplatId;
            vkCmdClearColorImage(cmd, splat_id_.Get(), VK_IMAGE_LAYOUT_GENERAL, &none, 1, &all);
        }
        ++counters_.skipped_composites;
    } else {
        CompositeStageInputs inputs;
        inputs.projected = geometry_stage_resources_.ViewResources().projected.Range();
        inputs.entry_keys = geometry_stage_resources_.ViewResources().entry_keys.Range();
        inputs.entry_values = geometry_stage_resources_.ViewResources().entry_values.Range();
        inputs.entry_count = geometry_stage_resources_.ViewResources().counters.Range(
            offsetof(shader::GaussianGeometryStageCounters, entry_count), sizeof(uint32_t));
        inputs.entry_capacity = geometry_stage_resources_.EntryCapacity();
        inputs.ranges_written = geometry_.tile_ranges_written;
        CompositeStageTargets targets;
        targets.width = w;
        targets.height = h;
        targets.color_format = color.GetFormat() == ToVkFormat(CompositeColorFormat::kRgba16f)
                                   ? CompositeColorFormat::kRgba16f
                                   : CompositeColorFormat::kRgba32f;
        targets.color = color.GetView();
        targets.depth = depth_.GetView();
        targets.alpha = alpha_.GetView();
        targets.median_depth = median_.GetView();
        targets.splat_id = frame.splat_id ? splat_id_.GetView() : VK_NULL_HANDLE;
        composite_stage_timestamps_.RecordBegin(cmd, TimedPass::kComposite);
        composite_stage_.RecordComposite(cmd, inputs, targets, composite_state_.Range(), params);
        composite_stage_timestamps_.RecordEnd(cmd, TimedPass::kComposite);
    }
    sink.RecordAfter(frame);
}

RenderStats GaussianSplatVulkanBackend::RenderComposite(CompositeSink& sink) {
    if (!geometry_.valid)
        core::ThrowError("Vulkan backend: a composite before RenderGeometryStage");
    const auto start = std::chrono::steady_clock::now();
    const uint32_t w = static_cast<uint32_t>(geometry_.camera.width);
    const uint32_t h = static_cast<uint32_t>(geometry_.camera.height);
    const Image& color = sink.ColorTarget();
    if (color.GetWidth() != w || color.GetHeight() != h) {
        core::ThrowError("Vulkan backend: the composite targets are {}x{}, the camera is {}x{}",
                         color.GetWidth(), color.GetHeight(), w, h);
    }
    // Another API's signal: a held geometry stage waits for it, else the composite does.
    VkSemaphore wait = sink.TakeWaitSemaphore();
    hold_geometry_submit_ = wait != VK_NULL_HANDLE;
    if (geometry_held_) {
        SubmitHeldGeometry(wait);
        if (wait != VK_NULL_HANDLE) ++counters_.held_geometry_stages;
        wait = VK_NULL_HANDLE;
    }
    // Behind the geometry stage, no host wait between them, where the sink allows it and the
    // last counters left the entry buffers a quarter free (an overflow is then unlikely and
    // is found after the composite); otherwise the counters come first.
    const bool behind =
        sink.SubmitsBehindGeometry() && geometry_.in_flight && entries_have_room_ && !growing_;
    const auto geometry_wait_start = std::chrono::steady_clock::now();
    if (!behind) WaitForGeometry();
    WaitForComposite();
    const double geometry_wait_ms = core::MillisecondsSince(geometry_wait_start);
    EnsureTargets(w, h);
    shader::GaussianGeometryStageCounters gpu_counters{};
    bool empty = false;
    if (!behind) {
        gpu_counters = ReadStageCounters();
        // The allocation, not the config, cut this frame short: render it again with room
        // before anything is composited (the sink's semaphores are taken by the frame that
        // runs). Geometry stage reported the full request, so one retry suffices.
        if (EntriesOutgrewBuffers(gpu_counters)) {
            return RenderAgainWithGrownBuffers(sink, gpu_counters);
        }
        // Nothing to blend (everything culled or hidden): no composite dispatch, the images
        // are cleared to the background instead.
        empty = gpu_counters.entry_count == 0;
    }

    CompositeParams params;
    for (int c = 0; c < 3; ++c)
        params.background[c] = static_cast<float>(geometry_.config.background[c]);
    sink.AdjustParams(params);

    // The recording names the targets, the entry buffers and the parameters, nothing of the
    // camera: while none of them changes (a sink's RecordingKey, the same size, scene and
    // buffers) the last one is submitted again.
    const std::string sink_key = sink.RecordingKey();
    std::string key;
    if (!sink_key.empty()) {
        const SceneDepthTexture none;
        const SceneDepthTexture& scene = params.scene_depth ? *params.scene_depth : none;
        const GeometryStageViewResources& buffers = geometry_stage_resources_.ViewResources();
        key = fmt::format(
            "{}|{}x{} empty {} bg {} {} {} scene {} {} {} {} {} outputs {} {} {} {} "
            "entries {} {} {} {} scene {} sort {}",
            sink_key, w, h, empty, params.background[0], params.background[1], params.background[2],
            params.scene_depth != nullptr, static_cast<const void*>(scene.view), int(scene.layout),
            scene.near_plane, scene.flip_y, params.expected_depth, params.median_depth,
            params.splat_id, params.max_workgroups, geometry_stage_resources_.EntryCapacity(),
            static_cast<const void*>(buffers.projected.Get()),
            static_cast<const void*>(buffers.entry_keys.Get()),
            static_cast<const void*>(depth_.GetView()), scene_serial_,
            int(geometry_.config.sort_mode));
    }
    const auto record_start = std::chrono::steady_clock::now();
    const bool reuse =
        !key.empty() && composite_cmd_.Get() != VK_NULL_HANDLE && key == composite_recorded_;
    if (reuse) {
        ++counters_.composite_reuses;
    } else {
        composite_cmd_ = pool_.Allocate();
        composite_cmd_.Begin(/*one_time_submit=*/false);
        RecordCompositeFrame(sink, composite_cmd_.Get(), params, empty);
        composite_cmd_.End();
        composite_recorded_ = key;
    }
    const VkCommandBuffer cmd = composite_cmd_.Get();
    if (!composite_fence_) {
        composite_fence_ = CreateFence(*context_);
    } else {
        ResetFence(*context_, composite_fence_.Get());
    }
    const double record_ms = core::MillisecondsSince(record_start);
    const auto submit_start = std::chrono::steady_clock::now();
    const VkSemaphore signal = sink.TakeSignalSemaphore();
    SubmitToQueue(context_->GetQueue(), cmd, composite_fence_.Get(), wait,
                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, signal);
    const double submit_ms = core::MillisecondsSince(submit_start);
    ++counters_.composites;
    // Another API waits for the frame on the GPU and the host reads nothing: no wait here.
    const bool waited = signal == VK_NULL_HANDLE || sink.ReadsBack();
    const auto wait_start = std::chrono::steady_clock::now();
    if (waited) {
        Wait(*context_, composite_fence_.Get());
        if (behind) {
            WaitForGeometry();  // signalled: it ran before the composite
            gpu_counters = ReadStageCounters();
            if (EntriesOutgrewBuffers(gpu_counters)) {
                return RenderAgainWithGrownBuffers(sink, gpu_counters);
            }
        }
    } else {
        composite_in_flight_ = true;
        composite_in_flight_empty_ = empty;
        composite_counters_pending_ = behind;
    }
    const double wait_ms = core::MillisecondsSince(wait_start);
    // Not waited for and behind: this frame's counters come with its fence, the stats give
    // the last ones read (as its GPU times give the last composite's).
    const bool counted = waited || !behind;
    if (!counted) gpu_counters = last_counters_;
    if (counted) WarnNewFlags(gpu_counters.error_flags);
    const auto readback_start = std::chrono::steady_clock::now();
    sink.ReadBack();

    // A reused geometry stage did no work this frame: its times stay 0.
    RenderStats s = geometry_.reused ? RenderStats{} : geometry_.times;
    FillCounterStats(gpu_counters, s);
    s.geometry_reused = geometry_.reused;
    s.composite_ms = core::MillisecondsSince(start);
    if (waited) {
        const std::vector<double> ms = composite_stage_timestamps_.ReadMilliseconds();
        s.gpu_composite_ms = empty ? 0.0 : PassMs(ms, TimedPass::kComposite);
        s.gpu_merge_ms = PassMs(ms, TimedPass::kDepthMerge);
    } else {
        s.gpu_composite_ms = last_composite_gpu_ms_;  // still running: the last one waited for
    }
    // The geometry stage's recording and submission (0 when reused), then this frame's.
    s.host_record_ms += record_ms;
    s.host_submit_ms += submit_ms;
    s.host_wait_ms = geometry_wait_ms + wait_ms;
    s.host_readback_ms = core::MillisecondsSince(readback_start);
    if (!geometry_.reused && counted) {
        ObserveLodFrame(geometry_.config, s.gpu_project_ms + s.gpu_sort_ms + s.gpu_composite_ms);
    }
    return s;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
