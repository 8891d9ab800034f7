#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "open3d/core/Timer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/core/Logging.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

bool SameCamera(const camera::PinholeCamera& a, const camera::PinholeCamera& b) {
    return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
           a.cx == b.cx && a.cy == b.cy && a.world_to_camera == b.world_to_camera;
}

// After the composite (compute writes) or the empty-frame clear (transfer writes).
void ToTransferSrc(VkCommandBuffer cmd, const Image& image, VkPipelineStageFlags2 stage,
                   VkAccessFlags2 access) {
    RecordImageBarrier(cmd, image.Get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                       VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, stage, access,
                       VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
}

}  // namespace

void GaussianSplatVulkanBackend::WarnNewFlags(uint32_t flags) {
    const uint32_t new_flags = flags & ~warned_flags_;
    if (new_flags & kEntriesDropped) {
        core::LogWarning(
            "Gaussian splat Vulkan backend: tile entries were dropped (a splat touches more "
            "than max_tiles_per_splat tiles or the entries exceed max_tile_entries_total)");
    }
    if (new_flags & kCountsClamped) {
        core::LogWarning(
            "Gaussian splat Vulkan backend: geometry stage counts were clamped to the "
            "allocated tile-entry capacity");
    }
    warned_flags_ |= flags;
}

uint32_t GaussianSplatVulkanBackend::MaxEntryCapacity(const RenderConfig& config,
                                                      uint32_t sort_max_count) {
    return static_cast<uint32_t>(std::min<uint64_t>(
        {config.max_tile_entries_total, shader::kScanSaturation - 1, sort_max_count}));
}

uint32_t GaussianSplatVulkanBackend::SortMaxCount() const {
    return RadixSort::MaxCountFor(context_->GetDeviceInfo());
}

GaussianSplatVulkanBackend::GaussianSplatVulkanBackend(std::unique_ptr<VulkanContext> context,
                                                       uint32_t initial_entry_capacity)
    : context_(std::move(context)),
      pool_(*context_),
      geometry_stage_(*context_),
      composite_stage_(*context_),
      geometry_stage_timestamps_(*context_),
      composite_stage_timestamps_(*context_),
      initial_entry_capacity_(std::max(1u, initial_entry_capacity)) {
    if (context_->HasTransferQueue()) {
        transfer_pool_ =
            std::make_unique<CommandPool>(*context_, context_->GetTransferQueueFamilyIndex());
    }
    // On a CPU device (lavapipe) a second frame in flight competes with the first for the
    // same cores: 245 against 230 ms per frame on 2 cores.
    SetFramesInFlight(context_->GetDeviceInfo().type == "CPU" ? 1 : 2);
    if (const char* env = std::getenv("OPEN3D_VULKAN_HOLD_GEOMETRY");
        env != nullptr && *env != '\0') {
        const std::string mode(env);
        if (mode != "0" && mode != "1") {
            core::ThrowError("OPEN3D_VULKAN_HOLD_GEOMETRY is '{}': 0 or 1", mode);
        }
        hold_geometry_enabled_ = mode == "1";
    }
}

GaussianSplatVulkanBackend::~GaussianSplatVulkanBackend() {
    // Nothing may still run on buffers we are about to free.
    WaitForStageWork();
    WaitAllSlots();
}

void GaussianSplatVulkanBackend::ReleaseResources() {
    WaitForStageWork();
    SetFramesInFlight(GetFramesInFlight());  // waits for the slots and empties them
    deferred_.Clear();
    geometry_ = GeometryState{};
    stage_recording_valid_ = false;
    composite_recorded_.clear();
    cloud_.reset();
    visibility_mask_.clear();
    geometry_stage_resources_ = GeometryStageResources();
    for (Buffer* buffer : {&counters_readback_, &color_readback_, &depth_readback_,
                           &median_readback_, &splat_id_readback_}) {
        *buffer = Buffer();
    }
    for (Image* image : {&depth_, &alpha_, &median_, &color_, &splat_id_}) *image = Image();
    width_ = height_ = 0;
}

void GaussianSplatVulkanBackend::EnsureViewBuffers(uint32_t entry_capacity) {
    if (geometry_stage_resources_.HasView() &&
        entry_capacity <= geometry_stage_resources_.EntryCapacity()) {
        return;
    }
    geometry_stage_resources_.AllocateView(*context_, entry_capacity);
    stage_recording_valid_ = false;  // it binds the old buffers
    composite_recorded_.clear();
    counters_readback_ = Buffer(*context_, sizeof(shader::GaussianGeometryStageCounters),
                                VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::kHostReadback);
}

void GaussianSplatVulkanBackend::EnsureTargets(uint32_t width, uint32_t height) {
    if (depth_ && width == width_ && height == height_) return;
    const CompositeStageStorageRequirements need = GaussianCompositeStage::GetStorageRequirements();
    const VkImageUsageFlags usage =
        need.image_usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    depth_ = Image(*context_, width, height, need.scalar_format, usage);
    alpha_ = Image(*context_, width, height, need.scalar_format, usage);
    median_ = Image(*context_, width, height, need.scalar_format, usage);
    composite_state_ = Buffer(*context_, GaussianCompositeStage::StateBytes(width, height),
                              need.state_usage, MemoryUsage::kDevice);
    stage_recording_valid_ = false;  // its per-tile bins name the old state buffer
    composite_recorded_.clear();
    width_ = width;
    height_ = height;
}

void GaussianSplatVulkanBackend::EnsureReadback(uint32_t width, uint32_t height) {
    if (color_ && color_.GetWidth() == width && color_.GetHeight() == height) return;
    const VkImageUsageFlags usage = GaussianCompositeStage::GetStorageRequirements().image_usage |
                                    VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                    VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    const auto readback = [&](uint32_t texel_bytes) {
        return Buffer(*context_, VkDeviceSize(width) * height * texel_bytes,
                      VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::kHostReadback);
    };
    color_ = Image(*context_, width, height, ToVkFormat(CompositeColorFormat::kRgba32f), usage);
    color_readback_ = readback(16);
    depth_readback_ = readback(4);
    median_readback_ = readback(4);
}

bool GaussianSplatVulkanBackend::WaitGeometryStage(double timeout_ms) {
    if (!geometry_.in_flight) return true;
    SubmitHeldGeometry(VK_NULL_HANDLE);
    // The fence stays signalled: the composite stage's own wait returns at once.
    VkFence fence = geometry_stage_fence_.Get();
    const VkResult result = vkWaitForFences(context_->GetDevice(), 1, &fence, VK_TRUE,
                                            static_cast<uint64_t>(std::max(0.0, timeout_ms) * 1e6));
    if (result == VK_TIMEOUT) return false;
    CheckVk(result, "vkWaitForFences");
    return true;
}

void GaussianSplatVulkanBackend::RenderGeometryStage(const camera::PinholeCamera& camera,
                                                     const RenderConfig& requested) {
    if (!cloud_) core::ThrowError("Vulkan backend: RenderGeometryStage before SetScene");
    camera.Validate();
    requested.Validate();
    const RenderConfig config = WithLodTarget(requested);
    const auto start = std::chrono::steady_clock::now();
    const SplatPrecision precision = SplatPrecisionFor(config.compact_storage);
    if (precision != geometry_stage_resources_.Layout().precision) {
        WaitForStageWork();
        geometry_.in_flight = false;
        UploadScene(precision);
        geometry_.valid = false;
    }
    if (config.reuse_geometry && geometry_.valid && SameCamera(camera, geometry_.camera) &&
        SameGeometryConfig(config, geometry_.config)) {
        // The composite's settings (the background) are this frame's, not the last run's.
        geometry_.config = config;
        geometry_.reused = true;
        ++counters_.geometry_reuses;
        return;
    }
    WaitForStageWork();
    CheckViewFits(static_cast<uint32_t>(camera.width), static_cast<uint32_t>(camera.height));
    // Per-tile bins leave each tile's range in the composite's state: it must be this
    // size's before the geometry stage is recorded.
    EnsureTargets(static_cast<uint32_t>(camera.width), static_cast<uint32_t>(camera.height));

    EnsureViewBuffers(static_cast<uint32_t>(
        std::min<uint64_t>(MaxEntryCapacity(config, SortMaxCount()), initial_entry_capacity_)));

    const PackedView view = geometry_stage_resources_.ViewParams(camera, config);

    const auto record_start = std::chrono::steady_clock::now();
    // The camera goes through host memory, so the recording is submitted again while the
    // scene, the config and the size stay (the viewer's frames): recording took ~0.5 ms of
    // host time per frame on the H200's host.
    if (!stage_params_upload_) {
        stage_params_upload_ = Buffer(*context_, sizeof(shader::GaussianViewParams),
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::kHostUpload);
    }
    std::memcpy(stage_params_upload_.GetMapped(), &view.params, sizeof(view.params));
    FrameRecordingKey key;
    key.views = 1;
    key.width = static_cast<uint32_t>(camera.width);
    key.height = static_cast<uint32_t>(camera.height);
    key.entry_capacity = geometry_stage_resources_.EntryCapacity();
    key.scene_serial = scene_serial_;
    key.choices = view.choices;
    key.config = config;
    const bool reuse = stage_recording_valid_ && stage_recorded_ == key;
    VkCommandBuffer cmd = geometry_stage_cmd_.Get();
    if (!reuse) {
        if (cmd == VK_NULL_HANDLE) geometry_stage_cmd_ = pool_.Allocate();
        cmd = geometry_stage_cmd_.Get();
        geometry_stage_cmd_.Begin(/*one_time_submit=*/false);
        geometry_stage_timestamps_.RecordReset(cmd);
        const BufferRange source = stage_params_upload_.Range();
        GeometryStageViewBuffers buffers = geometry_stage_resources_.View();
        buffers.tile_ranges = composite_state_.Range();
        geometry_stage_.Record(cmd, geometry_stage_resources_.Scene(), buffers, view,
                               &geometry_stage_timestamps_, &source);
        // The counters reach the host with the geometry stage's fence: composite stage can
        // skip an empty frame.
        RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                            VK_ACCESS_2_TRANSFER_READ_BIT);
        const VkBufferCopy counters_region{0, 0, counters_readback_.GetSize()};
        vkCmdCopyBuffer(cmd, geometry_stage_resources_.ViewResources().counters.Get(),
                        counters_readback_.Get(), 1, &counters_region);
        RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        geometry_stage_cmd_.End();
        stage_recorded_ = key;
        stage_recording_valid_ = true;
        ++counters_.recordings;
    }
    if (!geometry_stage_fence_) {
        geometry_stage_fence_ = CreateFence(*context_);
    } else {
        ResetFence(*context_, geometry_stage_fence_.Get());
    }
    const double record_ms = reuse ? 0.0 : core::MillisecondsSince(record_start);
    const auto submit_start = std::chrono::steady_clock::now();
    // Fire and forget: composite stage (or the next geometry stage) waits on the fence. Held
    // for the composite where that waits for GL (hold_geometry_submit_).
    if (hold_geometry_submit_ && hold_geometry_enabled_) {
        geometry_held_ = true;
    } else {
        Submit(*context_, cmd, geometry_stage_fence_.Get());
    }
    const double submit_ms = core::MillisecondsSince(submit_start);
    ++counters_.geometry_runs;
    geometry_.camera = camera;
    geometry_.config = config;
    geometry_.tile_ranges_written = geometry_stage_.WritesTileRanges(view.choices);
    geometry_.valid = true;
    geometry_.in_flight = true;
    geometry_.reused = false;
    geometry_.times = RenderStats{};
    geometry_.times.geometry_ms = core::MillisecondsSince(start);
    geometry_.times.host_record_ms = record_ms;
    geometry_.times.host_submit_ms = submit_ms;
}

// RenderCompositeStage's sink: the backend's RGBA32F colour image, the scene depth uploaded
// from CompositeInputs, every image copied to its host buffer.
class GaussianSplatVulkanBackend::ReadbackSink final : public CompositeSink {
public:
    ReadbackSink(GaussianSplatVulkanBackend& backend, const CompositeInputs& inputs,
                 RenderOutput& output)
        : backend_(backend),
          output_(output),
          read_back_(inputs.read_back),
          expected_depth_(inputs.expected_depth),
          median_depth_(inputs.median_depth),
          splat_id_(inputs.splat_id) {
        const uint32_t w = backend.color_.GetWidth(), h = backend.color_.GetHeight();
        // Through a hierarchy the composite blends the cut's list slots. Only a cut of every
        // leaf lists the leaves in order (slot i is node i, splat i of the cloud): any other
        // cut's pixels show merged nodes, not splats of the cloud.
        if (splat_id_ && backend.geometry_stage_resources_.HasLod()) {
            const uint64_t budget = backend.geometry_.config.lod_budget;
            if (budget != 0 && budget < backend.geometry_stage_resources_.LodLeaves()) {
                core::ThrowError(
                    "Vulkan backend: no ID image for a level-of-detail cut of at most {} of {} "
                    "splats (its pixels show merged nodes, not splats of the cloud); a budget "
                    "of 0 draws every splat",
                    budget, backend.geometry_stage_resources_.LodLeaves());
            }
        }
        if (splat_id_ && (!backend.splat_id_ || backend.splat_id_.GetWidth() != w ||
                          backend.splat_id_.GetHeight() != h)) {
            backend.splat_id_ =
                Image(*backend.context_, w, h, kSplatIdFormat,
                      GaussianCompositeStage::GetStorageRequirements().image_usage |
                          VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
            backend.splat_id_readback_ =
                Buffer(*backend.context_, VkDeviceSize(w) * h * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                       MemoryUsage::kHostReadback);
        }
        if (inputs.scene_depth == nullptr || inputs.scene_depth->IsEmpty()) return;
        // Scene depth (view z) becomes Filament's reversed-Z texture d = near / z.
        const t::geometry::Image& z = *inputs.scene_depth;
        if (z.GetRows() != h || z.GetCols() != w || z.GetChannels() != 1 ||
            z.GetDtype() != core::Dtype::Float32) {
            core::ThrowError("Vulkan backend: scene depth must be Float32 [{}, {}, 1]", h, w);
        }
        const VulkanContext& context = *backend.context_;
        scene_.near_plane = static_cast<float>(backend.geometry_.config.near_plane);
        scene_upload_ = Buffer(context, VkDeviceSize(w) * h * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                               MemoryUsage::kHostUpload);
        float* d = static_cast<float*>(scene_upload_.GetMapped());
        const float* src = z.Data<float>();
        for (size_t i = 0; i < size_t(w) * h; ++i) {
            d[i] = src[i] > 0.0f && std::isfinite(src[i]) ? scene_.near_plane / src[i] : 0.0f;
        }
        scene_image_ = Image(context, w, h, VK_FORMAT_D32_SFLOAT,
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
        scene_.view = scene_image_.GetView();
    }

    const Image& ColorTarget() const override { return backend_.color_; }

    void AdjustParams(CompositeParams& params) const override {
        params.scene_depth = scene_image_ ? &scene_ : nullptr;
        params.expected_depth = expected_depth_;
        params.median_depth = median_depth_;
        params.splat_id = splat_id_;
    }

    void RecordBefore(const Frame& frame) override {
        RecordImageBarrier(frame.cmd, backend_.color_.Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                           VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                           VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                           frame.write_stage, frame.write_access);
        if (scene_image_) RecordDepthTextureUpload(frame.cmd, scene_image_, scene_upload_.Get());
    }

    void RecordAfter(const Frame& frame) override {
        if (!read_back_) return;
        // The alpha image is the colour's alpha channel: only the depth merge reads it.
        const std::pair<const Image*, const Buffer*> copies[] = {
            {&backend_.color_, &backend_.color_readback_},
            {expected_depth_ ? frame.depth : nullptr, &backend_.depth_readback_},
            {median_depth_ ? frame.median : nullptr, &backend_.median_readback_},
            {frame.splat_id, &backend_.splat_id_readback_}};
        for (const auto& [image, buffer] : copies) {
            if (image == nullptr) continue;
            ToTransferSrc(frame.cmd, *image, frame.write_stage, frame.write_access);
            RecordCopyToBuffer(frame.cmd, *image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               buffer->Get());
        }
    }

    void ReadBack() override {
        if (!read_back_) return;
        const size_t pixels = size_t(backend_.width_) * backend_.height_;
        const int64_t h = backend_.height_, w = backend_.width_;
        output_.color = t::geometry::Image(h, w, 4, core::Dtype::Float32);
        std::memcpy(output_.color.Data<float>(), backend_.color_readback_.GetMapped(), pixels * 16);
        // An R32F image that was asked for, else empty.
        const auto scalar = [&](bool wanted, const Buffer& readback) {
            if (!wanted) return t::geometry::Image();
            t::geometry::Image image(h, w, 1, core::Dtype::Float32);
            std::memcpy(image.Data<float>(), readback.GetMapped(), pixels * 4);
            return image;
        };
        output_.depth_expected = scalar(expected_depth_, backend_.depth_readback_);
        output_.depth_median = scalar(median_depth_, backend_.median_readback_);
        // The R32_UINT image's bits are the int32 IDs (kCompositeNoSplat is -1).
        output_.splat_id = t::geometry::Image();
        if (splat_id_) {
            output_.splat_id = t::geometry::Image(h, w, 1, core::Dtype::Int32);
            std::memcpy(output_.splat_id.Data<int32_t>(), backend_.splat_id_readback_.GetMapped(),
                        pixels * 4);
        }
    }

private:
    GaussianSplatVulkanBackend& backend_;
    RenderOutput& output_;
    const bool read_back_;
    const bool expected_depth_;
    const bool median_depth_;
    const bool splat_id_;
    Image scene_image_;
    Buffer scene_upload_;
    SceneDepthTexture scene_;
};

void GaussianSplatVulkanBackend::RenderCompositeStage(RenderOutput& output,
                                                      const CompositeInputs& inputs) {
    if (!geometry_.valid)
        core::ThrowError("Vulkan backend: RenderCompositeStage before RenderGeometryStage");
    // The colour target exists with or without readback (the composite writes it).
    EnsureReadback(static_cast<uint32_t>(geometry_.camera.width),
                   static_cast<uint32_t>(geometry_.camera.height));
    ReadbackSink sink(*this, inputs, output);
    output.stats = RenderComposite(sink);
}

void GaussianSplatVulkanBackend::WaitForGeometry() {
    if (!geometry_.in_flight) return;
    SubmitHeldGeometry(VK_NULL_HANDLE);
    Wait(*context_, geometry_stage_fence_.Get());
    geometry_.in_flight = false;
    const std::vector<double> ms = geometry_stage_timestamps_.ReadMilliseconds();
    const auto at = [&](TimedPass pass) { return PassMs(ms, pass); };
    RenderStats& t = geometry_.times;
    t.gpu_project_ms = at(TimedPass::kProject);
    t.gpu_sort_ms = at(TimedPass::kSort);
    t.gpu_depth_sort_ms = at(TimedPass::kDepthSort);
    t.gpu_scan_emit_ms = at(TimedPass::kScanEmit);
    t.gpu_tile_sort_ms = at(TimedPass::kTileSort);
    t.gpu_lod_cut_ms = geometry_stage_resources_.HasLod() ? at(TimedPass::kLodCut) : 0.0;
    t.gpu_lod_list_ms = geometry_stage_resources_.HasLod() ? at(TimedPass::kLodCutList) : 0.0;
}

RenderConfig GaussianSplatVulkanBackend::WithLodTarget(const RenderConfig& config) {
    if (!(config.lod_target_ms > 0.0) || !geometry_stage_resources_.HasLod()) return config;
    RenderConfig frame = config;
    frame.lod_budget = lod_controller_.NextBudget(
        config.lod_target_ms, geometry_stage_resources_.LodLeaves(), config.lod_budget);
    return frame;
}

void GaussianSplatVulkanBackend::ObserveLodFrame(const RenderConfig& frame_config, double gpu_ms) {
    if (frame_config.lod_target_ms > 0.0 && geometry_stage_resources_.HasLod()) {
        lod_controller_.Observe(frame_config.lod_budget, gpu_ms);
    }
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
