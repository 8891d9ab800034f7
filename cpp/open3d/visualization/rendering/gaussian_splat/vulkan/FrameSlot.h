// One frame in flight of the Vulkan backend's submission path (SubmitBatch / Render): its own
// geometry-stage buffers, composite targets, per-view output buffers and a command buffer that
// is recorded once and submitted again while the scene, the config, the size and the outputs
// stay the same (a new camera is a write into `params_upload`). Two or three slots let the
// host prepare frame k + 1 while the GPU runs frame k; nothing here is shared between slots
// but the scene, so a slot's buffers are only touched after its own fence.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianCompositeStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStageResources.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GpuTimestamps.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Image.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// What a recording depends on. Equal keys: the recorded command buffer is submitted again.
/// Bytes per pixel of a batch's colour target: RGBA8 or RGBA32F.
inline VkDeviceSize ColorBytesPerPixel(const BatchOptions& options) {
    return options.color_uint8 ? 4 : 16;
}

struct FrameRecordingKey {
    uint32_t views = 0, width = 0, height = 0;
    uint32_t entry_capacity = 0;
    uint64_t scene_serial = 0;  ///< bumped by every scene, mask or precision upload
    GeometryStageChoices choices;
    RenderConfig config;
    BatchOptions options;  ///< without its destination (which the readback copy names)
    /// The colours go to imported host memory: the slot keeps no host colour buffer.
    bool color_imported = false;
    /// RGBA32F into imported memory: the composite writes the colours straight into it
    /// (this buffer, the submission's first view at this offset); no copy.
    VkBuffer direct_color = VK_NULL_HANDLE;
    VkDeviceSize direct_color_offset = 0;
    bool operator==(const FrameRecordingKey& other) const;
};

struct FrameSlot {
    explicit FrameSlot(const VulkanContext& context)
        : pass_timestamps(context), job_timestamps(context, 1) {}

    GeometryStageViewResources view;
    // Composite targets of the slot's size (one set: the views of a job run one after another).
    Image color, depth, alpha, median;
    Buffer composite_state;
    uint32_t width = 0, height = 0;
    CompositeColorFormat color_format = CompositeColorFormat::kRgba32f;

    // Per view of the job: parameters written by the host, counters read back, the images on
    // the device (one buffer per kind, view i at i * image bytes) and their host copies.
    Buffer params_upload, counters_readback;
    Buffer device_color, device_depth, device_median;
    Buffer host_color, host_depth, host_median;
    uint32_t view_capacity = 0;  ///< views the per-view buffers hold

    CommandBuffer cmd;
    // With readback: the copies to host memory, in their own command buffer, re-recorded
    // alone when only their destination changes (a batch split over imported memory puts
    // each submission at another offset). With a transfer queue they run on the copy engines
    // (after `rendered`), overlapping the next submission's compute work; without one they
    // follow `cmd` on the same queue.
    CommandBuffer copy_cmd;
    UniqueSemaphore rendered;
    /// With FrameRecordingKey::color_imported: the imported buffer and offset of this batch.
    VkBuffer imported_target = VK_NULL_HANDLE;
    VkDeviceSize imported_target_offset = 0;
    /// Where copy_cmd copies the colours (host_color at 0, or the import); VK_NULL_HANDLE
    /// when copy_cmd must be recorded again (a new recording).
    VkBuffer copied_color_target = VK_NULL_HANDLE;
    VkDeviceSize copied_color_target_offset = 0;
    UniqueFence fence;              ///< the last submission of the job
    uint64_t serial = 0;            ///< of the last submission
    bool in_flight = false;         ///< submitted, fence not waited for yet
    GpuTimestamps pass_timestamps;  ///< per pass, for one-view jobs
    GpuTimestamps job_timestamps;   ///< the whole job
    FrameRecordingKey recorded;
    bool has_recording = false;
    CommandCounts recorded_counts;  ///< what `cmd` holds (dispatches, barriers)
    /// Earlier recordings of this slot for other keys, kept while its buffers stay (each part
    /// of a batch split over imported memory has its own destination, so the slots take
    /// several in turn): a submission whose key one of them matches swaps it with `cmd`
    /// instead of recording. Cleared whenever has_recording is reset
    /// (GaussianSplatVulkanBackend::ForgetRecordings).
    struct SpareRecording {
        FrameRecordingKey key;
        CommandBuffer cmd;
        CommandCounts counts;
    };
    std::vector<SpareRecording> spare_recordings;

    // The batch in the slot, from SubmitBatch until its WaitBatch.
    bool pending = false;
    uint64_t ticket = 0;  ///< the serial of its first submission
    bool recording_reused = false;
    std::vector<camera::PinholeCamera> cameras;
    RenderConfig config;
    BatchOptions options;
    uint8_t* color_destination = nullptr;  ///< the caller's memory for the colours, if any
    double record_ms = 0.0, submit_ms = 0.0;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
