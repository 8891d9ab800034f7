// Images shared with GL (GaussianSplatInterop.h): exportable colour and depth images, their
// queue-family ownership transfers, and the composite into them (a CompositeSink of the
// Vulkan backend). Layouts and transfers: docs/vulkan.md "Zero-copy interop targets".
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatInterop.h"

#include <fmt/format.h>

#include <atomic>
#include <cstring>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

constexpr VkFormat kColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkFormat kMeshColorFormat = VK_FORMAT_R8G8B8A8_UNORM;

GaussianSplatVulkanBackend& RequireVulkan(GaussianSplatBackend& backend) {
    auto* vulkan = dynamic_cast<GaussianSplatVulkanBackend*>(&backend);
    if (vulkan == nullptr) {
        core::ThrowError("Gaussian splat interop needs the \"vulkan\" backend, not \"{}\"",
                         backend.GetName());
    }
    return *vulkan;
}

/// A queue-family ownership transfer of `image` between this queue's family and the
/// external one (GL), from `old_layout` to `new_layout`.
/// Acquire: the source scope is empty (GL's side has no stages here: the CPU ordered it with
/// glFinish); `stages`/`access` are the destination scope.
/// Release: `stages`/`access` are the source scope, the destination scope is empty, and the
/// transfer itself changes no layout (GL has no acquire barrier that could repeat the change,
/// and the validation layer would not apply it): a plain barrier before it does.
enum class Transfer { kAcquire, kRelease };
void RecordOwnershipTransfer(VkCommandBuffer cmd, const VulkanContext& context, const Image& image,
                             Transfer transfer, VkImageLayout old_layout, VkImageLayout new_layout,
                             VkPipelineStageFlags2 stages, VkAccessFlags2 access) {
    const bool acquire = transfer == Transfer::kAcquire;
    const VkImageAspectFlags aspect = AspectOf(image.GetFormat());
    if (!acquire && old_layout != new_layout) {
        RecordImageBarrier(cmd, image.Get(), aspect, old_layout, new_layout, stages, access,
                           VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_NONE);
        stages = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        access = VK_ACCESS_2_NONE;
        old_layout = new_layout;
    }
    const uint32_t ours = context.GetQueueFamilyIndex();
    if (acquire) {
        RecordImageBarrier(cmd, image.Get(), aspect, old_layout, new_layout,
                           VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, stages, access,
                           VK_QUEUE_FAMILY_EXTERNAL, ours);
    } else {
        RecordImageBarrier(cmd, image.Get(), aspect, old_layout, new_layout, stages, access,
                           VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, ours,
                           VK_QUEUE_FAMILY_EXTERNAL);
    }
}

VkImageUsageFlags ColorUsage(const VulkanContext& context) {
    VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                              VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    VkFormatProperties properties{};
    vkGetPhysicalDeviceFormatProperties(context.GetPhysicalDevice(), kColorFormat, &properties);
    if (properties.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT) {
        usage |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;  // GL may render into it too
    }
    return usage;
}

Buffer ReadbackBuffer(const VulkanContext& context, uint32_t width, uint32_t height,
                      uint32_t texel_bytes) {
    return Buffer(context, VkDeviceSize(width) * height * texel_bytes,
                  VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::kHostReadback);
}

}  // namespace

struct InteropTargets::Impl {
    Impl(GaussianSplatVulkanBackend& backend, uint32_t width, uint32_t height)
        : backend(backend), context(backend.GetContext()), pool(context) {
        color = Image(context, width, height, kColorFormat, ColorUsage(context),
                      ImageMemory::kExportableFd);
        depth = Image(context, width, height, kDepthFormat,
                      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                          VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                      ImageMemory::kExportableFd);
        // Filament's mesh colour (its colour attachment in GL), read by the blend over it.
        mesh_color = Image(context, width, height, kMeshColorFormat,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                               VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                           ImageMemory::kExportableFd);
        // Transparent colour and depth 0 ("nothing drawn" in reversed Z) until GL or a
        // composite writes them, then both go to the external queue family.
        SubmitAndWait(context, pool, [&](VkCommandBuffer cmd) {
            for (const Image* image : {&color, &depth, &mesh_color}) {
                RecordImageBarrier(cmd, image->Get(), AspectOf(image->GetFormat()),
                                   VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                                   VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                                   VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
            }
            const VkClearColorValue transparent{};
            const VkImageSubresourceRange color_range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdClearColorImage(cmd, color.Get(), VK_IMAGE_LAYOUT_GENERAL, &transparent, 1,
                                 &color_range);
            vkCmdClearColorImage(cmd, mesh_color.Get(), VK_IMAGE_LAYOUT_GENERAL, &transparent, 1,
                                 &color_range);
            const VkClearDepthStencilValue nothing{0.0f, 0};
            const VkImageSubresourceRange depth_range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
            vkCmdClearDepthStencilImage(cmd, depth.Get(), VK_IMAGE_LAYOUT_GENERAL, &nothing, 1,
                                        &depth_range);
            for (const Image* image : {&color, &depth, &mesh_color}) {
                RecordOwnershipTransfer(cmd, context, *image, Transfer::kRelease,
                                        VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL,
                                        VK_PIPELINE_STAGE_2_CLEAR_BIT,
                                        VK_ACCESS_2_TRANSFER_WRITE_BIT);
            }
        });
    }

    // The depth merge's outputs and the host buffers of what a request reads, made on first
    // use.
    void EnsureColorReadback() {
        if (!color_readback) color_readback = ReadbackBuffer(context, Width(), Height(), 8);
    }
    // The blend writes its RGBA8 words straight into host-readable memory.
    void EnsureBlendReadback() {
        if (blend_readback) return;
        blend_readback = Buffer(context, VkDeviceSize(Width()) * Height() * 4,
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::kHostReadback);
    }
    void EnsureDepthReadback() {
        if (merged_linear) return;
        const CompositeStageStorageRequirements need =
            GaussianCompositeStage::GetStorageRequirements();
        const VkImageUsageFlags usage = need.image_usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        merged_linear = Image(context, Width(), Height(), need.scalar_format, usage);
        merged_normalized = Image(context, Width(), Height(), need.normalized_depth_format, usage);
        linear_readback = ReadbackBuffer(context, Width(), Height(), 4);
        normalized_readback = ReadbackBuffer(context, Width(), Height(), 2);
    }
    uint32_t Width() const { return color.GetWidth(); }
    uint32_t Height() const { return color.GetHeight(); }

    GaussianSplatVulkanBackend& backend;
    const VulkanContext& context;
    CommandPool pool;
    Image color;       // RGBA16F, exported
    Image depth;       // D32_SFLOAT, exported
    Image mesh_color;  // RGBA8, exported
    Buffer color_readback;
    Buffer blend_readback;
    Image merged_linear, merged_normalized;
    Buffer linear_readback, normalized_readback;
    Buffer depth_upload;
    UniqueSemaphore mesh_drawn;    // exportable; made by ExportMeshDrawnSemaphore
    UniqueSemaphore splats_drawn;  // exportable; made by ExportSplatsDrawnSemaphore
    // Names these targets in composite recording keys (an address could be reused).
    const uint64_t serial = NextSerial();

private:
    static uint64_t NextSerial() {
        static std::atomic<uint64_t> next{1};
        return next++;
    }
};

namespace {

// RenderCompositeToInterop's sink: acquires the shared images, composites into the colour,
// tests against the shared depth, optionally merges depths and reads back, releases.
class InteropSink final : public CompositeSink {
public:
    InteropSink(InteropTargets::Impl& targets, const InteropCompositeRequest& request,
                InteropFrame& out)
        : targets_(targets), request_(request), out_(out) {
        if (request.use_scene_depth && !(request.scene_near > 0.f)) {
            core::ThrowError("Gaussian splat interop: scene_near must be > 0, not {}",
                             request.scene_near);
        }
        if (request.wait_mesh_drawn && !targets.mesh_drawn) {
            core::ThrowError(
                "Gaussian splat interop: a composite waits for the mesh-drawn semaphore, which "
                "was never exported");
        }
        if (request.signal_splats_drawn && !targets.splats_drawn) {
            core::ThrowError(
                "Gaussian splat interop: a composite signals the splats-drawn semaphore, which "
                "was never exported");
        }
        if (request.read_depth && !(request.depth_far > request.depth_near)) {
            core::ThrowError("Gaussian splat interop: depth range [{}, {}] is empty",
                             request.depth_near, request.depth_far);
        }
        // Filament's depth attachment: reversed Z, row 0 at the bottom, sampled in GENERAL.
        scene_.view = targets.depth.GetView();
        scene_.layout = VK_IMAGE_LAYOUT_GENERAL;
        scene_.near_plane = request.scene_near;
        scene_.flip_y = true;
        if (request.read_color) targets.EnsureColorReadback();
        if (request.blend_over_mesh) targets.EnsureBlendReadback();
        if (request.read_depth) targets.EnsureDepthReadback();
    }

    const Image& ColorTarget() const override { return targets_.color; }

    VkSemaphore TakeWaitSemaphore() override {
        if (!request_.wait_mesh_drawn || waited_) return VK_NULL_HANDLE;
        waited_ = true;  // a binary semaphore: one wait per signal (a retried frame waits none)
        return targets_.mesh_drawn.Get();
    }

    VkSemaphore TakeSignalSemaphore() override {
        if (!request_.signal_splats_drawn || signalled_) return VK_NULL_HANDLE;
        signalled_ = true;  // GL waits once per signal
        return targets_.splats_drawn.Get();
    }

    // The request and the targets name everything recorded: the images and, made once
    // each, the readback buffers.
    std::string RecordingKey() const override {
        return fmt::format("interop {} depth {} {} read {} {} {} {} {}", targets_.serial,
                           request_.use_scene_depth, request_.scene_near, request_.read_color,
                           request_.blend_over_mesh, request_.read_depth, request_.depth_near,
                           request_.depth_far);
    }

    // GL's frame waits for this composite (semaphore or host wait), never for the geometry
    // stage before it.
    bool SubmitsBehindGeometry() const override { return true; }

    bool ReadsBack() const override {
        return request_.read_color || request_.blend_over_mesh || request_.read_depth;
    }

    void AdjustParams(CompositeParams& params) const override {
        params.background = {0.f, 0.f, 0.f};  // premultiplied overlay: Filament has the background
        params.scene_depth = SceneDepth();
        // The depth merge reads the expected depth and alpha; nothing reads the median.
        params.expected_depth = request_.read_depth;
        params.median_depth = false;
    }

    void RecordBefore(const Frame& frame) override {
        // Colour: fully overwritten, so its old contents may go (UNDEFINED). Depth: keep what
        // Filament drew (GENERAL -> GENERAL; UNDEFINED would let the driver discard it).
        RecordOwnershipTransfer(frame.cmd, targets_.context, targets_.color, Transfer::kAcquire,
                                VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                                frame.write_stage, frame.write_access);
        RecordOwnershipTransfer(frame.cmd, targets_.context, targets_.depth, Transfer::kAcquire,
                                VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL,
                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        if (request_.blend_over_mesh) {
            RecordOwnershipTransfer(frame.cmd, targets_.context, targets_.mesh_color,
                                    Transfer::kAcquire, VK_IMAGE_LAYOUT_GENERAL,
                                    VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                    VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        }
    }

    void RecordAfter(const Frame& frame) override {
        const VkCommandBuffer cmd = frame.cmd;
        VkImageLayout color_layout = VK_IMAGE_LAYOUT_GENERAL;
        VkPipelineStageFlags2 color_stages = frame.write_stage;
        VkAccessFlags2 color_access = frame.write_access;
        if (request_.read_depth) RecordDepthMerge(frame);
        if (request_.blend_over_mesh) RecordBlendOver(frame);
        if (request_.read_color) {
            // Copied in TRANSFER_SRC_OPTIMAL; released in GENERAL.
            color_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
            RecordImageBarrier(cmd, targets_.color.Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                               VK_IMAGE_LAYOUT_GENERAL, color_layout, frame.write_stage,
                               frame.write_access, VK_PIPELINE_STAGE_2_COPY_BIT,
                               VK_ACCESS_2_TRANSFER_READ_BIT);
            RecordCopyToBuffer(cmd, targets_.color, color_layout, targets_.color_readback.Get());
            color_stages = VK_PIPELINE_STAGE_2_COPY_BIT;
            color_access = VK_ACCESS_2_NONE;  // a read: the execution dependency suffices
        }
        RecordOwnershipTransfer(cmd, targets_.context, targets_.color, Transfer::kRelease,
                                color_layout, VK_IMAGE_LAYOUT_GENERAL, color_stages, color_access);
        RecordOwnershipTransfer(cmd, targets_.context, targets_.depth, Transfer::kRelease,
                                VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL,
                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_NONE);
        if (request_.blend_over_mesh) {
            RecordOwnershipTransfer(cmd, targets_.context, targets_.mesh_color, Transfer::kRelease,
                                    VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL,
                                    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_NONE);
            // The host reads the blend's words after the fence.
            RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                                VK_ACCESS_2_HOST_READ_BIT);
        }
    }

    void ReadBack() override {
        const int64_t w = targets_.Width(), h = targets_.Height();
        const size_t pixels = size_t(w) * h;
        out_.color = t::geometry::Image();
        out_.blended = t::geometry::Image();
        out_.linear_depth = t::geometry::Image();
        out_.normalized_depth = t::geometry::Image();
        if (request_.read_color) {
            out_.color = t::geometry::Image(h, w, 4, core::Dtype::Float32);
            const auto* halves = static_cast<const uint16_t*>(targets_.color_readback.GetMapped());
            float* dst = out_.color.Data<float>();
            core::ParallelForRange(
                int64_t(pixels) * 4,
                [&](int64_t begin, int64_t end) {
                    for (int64_t i = begin; i < end; ++i) dst[i] = HalfToFloat(halves[i]);
                },
                int64_t(1) << 18);
        }
        if (request_.blend_over_mesh) {
            out_.blended = t::geometry::Image(h, w, 4, core::Dtype::UInt8);
            std::memcpy(out_.blended.Data<uint8_t>(), targets_.blend_readback.GetMapped(),
                        pixels * 4);
        }
        if (request_.read_depth) {
            out_.linear_depth = t::geometry::Image(h, w, 1, core::Dtype::Float32);
            out_.normalized_depth = t::geometry::Image(h, w, 1, core::Dtype::UInt16);
            std::memcpy(out_.linear_depth.Data<float>(), targets_.linear_readback.GetMapped(),
                        pixels * 4);
            std::memcpy(out_.normalized_depth.Data<uint16_t>(),
                        targets_.normalized_readback.GetMapped(), pixels * 2);
        }
    }

private:
    const SceneDepthTexture* SceneDepth() const {
        return request_.use_scene_depth ? &scene_ : nullptr;
    }

    // The splat colour over the mesh colour, into the host-readable RGBA8 words.
    void RecordBlendOver(const Frame& frame) {
        RecordMemoryBarrier(frame.cmd, frame.write_stage, frame.write_access,
                            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
        BlendOverImages images;
        images.width = targets_.Width();
        images.height = targets_.Height();
        images.splat_color = targets_.color.GetView();
        images.mesh_color = targets_.mesh_color.GetView();
        images.mesh_flip_y = true;
        images.output = targets_.blend_readback.Get();
        frame.composite_stage->RecordBlendOver(frame.cmd, images);
    }

    // Splat expected depth (where 1 - T >= 0.5) merged with the scene depth, both outputs
    // copied to their host buffers.
    void RecordDepthMerge(const Frame& frame) {
        const VkCommandBuffer cmd = frame.cmd;
        RecordMemoryBarrier(cmd, frame.write_stage, frame.write_access,
                            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
        const Image* merged[] = {&targets_.merged_linear, &targets_.merged_normalized};
        for (const Image* image : merged) {
            // The last frame's copy read it.
            RecordImageBarrier(cmd, image->Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                               VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                               VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                               VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
        DepthMergeImages images;
        images.width = targets_.Width();
        images.height = targets_.Height();
        images.splat_depth = frame.depth->GetView();
        images.splat_alpha = frame.alpha->GetView();
        images.linear = targets_.merged_linear.GetView();
        images.normalized = targets_.merged_normalized.GetView();
        DepthMergeParams params;
        params.near = request_.depth_near;
        params.far = request_.depth_far;
        params.min_alpha = 0.5f;
        params.scene_depth = SceneDepth();
        frame.timestamps->RecordBegin(cmd, TimedPass::kDepthMerge);
        frame.composite_stage->RecordDepthMerge(cmd, images, params);
        frame.timestamps->RecordEnd(cmd, TimedPass::kDepthMerge);
        const Buffer* buffers[] = {&targets_.linear_readback, &targets_.normalized_readback};
        for (int i = 0; i < 2; ++i) {
            RecordImageBarrier(cmd, merged[i]->Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                               VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                               VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                               VK_ACCESS_2_TRANSFER_READ_BIT);
            RecordCopyToBuffer(cmd, *merged[i], VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               buffers[i]->Get());
        }
    }

    InteropTargets::Impl& targets_;
    const InteropCompositeRequest& request_;
    InteropFrame& out_;
    SceneDepthTexture scene_;
    bool waited_ = false;
    bool signalled_ = false;
};

}  // namespace

InteropSupport QueryInteropSupport(const GaussianSplatBackend& backend) {
    InteropSupport support;
    const auto* vulkan = dynamic_cast<const GaussianSplatVulkanBackend*>(&backend);
    if (vulkan == nullptr) return support;
    const VulkanContext& context = vulkan->GetContext();
    support.external_memory_fd = context.SupportsExternalMemoryFd();
    support.external_semaphore_fd = context.SupportsExternalSemaphoreFd();
    support.device_uuid = context.GetDeviceInfo().device_uuid;
    support.driver_uuid = context.GetDeviceInfo().driver_uuid;
    return support;
}

InteropTargets::InteropTargets(GaussianSplatBackend& backend, uint32_t width, uint32_t height) {
    GaussianSplatVulkanBackend& vulkan = RequireVulkan(backend);
    if (!vulkan.GetContext().SupportsExternalMemoryFd()) {
        core::ThrowError(
            "Gaussian splat interop: the Vulkan device {} cannot export memory ({} is not "
            "enabled); render with readback instead",
            vulkan.GetContext().GetDeviceInfo().name, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
    }
    if (width == 0 || height == 0) {
        core::ThrowError("Gaussian splat interop: the images are {}x{}", width, height);
    }
    impl_ = std::make_unique<Impl>(vulkan, width, height);
}

InteropTargets::~InteropTargets() {
    // A composite GL waits for on the GPU may still write the images.
    if (impl_) impl_->backend.WaitForComposite();
}

uint32_t InteropTargets::GetWidth() const { return impl_->Width(); }
uint32_t InteropTargets::GetHeight() const { return impl_->Height(); }

ExportedImageMemory InteropTargets::ExportColor() {
    const ImageMemoryFd memory = impl_->color.ExportFd(impl_->context);
    return {memory.fd, memory.size, true};
}

ExportedImageMemory InteropTargets::ExportDepth() {
    const ImageMemoryFd memory = impl_->depth.ExportFd(impl_->context);
    return {memory.fd, memory.size, true};
}

ExportedImageMemory InteropTargets::ExportMeshColor() {
    const ImageMemoryFd memory = impl_->mesh_color.ExportFd(impl_->context);
    return {memory.fd, memory.size, true};
}

namespace {

int ExportSemaphore(const VulkanContext& context, UniqueSemaphore& semaphore) {
    if (!context.SupportsExternalSemaphoreFd()) {
        core::ThrowError(
            "Gaussian splat interop: the Vulkan device {} cannot export semaphores ({} is not "
            "enabled)",
            context.GetDeviceInfo().name, VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    }
    if (!semaphore) semaphore = CreateBinarySemaphore(context, true);
    VkSemaphoreGetFdInfoKHR info =
        MakeInfo<VkSemaphoreGetFdInfoKHR>(VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR);
    info.semaphore = semaphore.Get();
    info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    int fd = -1;
    CheckVk(context.GetSemaphoreFd()(context.GetDevice(), &info, &fd), "vkGetSemaphoreFdKHR");
    return fd;
}

}  // namespace

int InteropTargets::ExportMeshDrawnSemaphore() {
    return ExportSemaphore(impl_->context, impl_->mesh_drawn);
}

int InteropTargets::ExportSplatsDrawnSemaphore() {
    return ExportSemaphore(impl_->context, impl_->splats_drawn);
}

void InteropTargets::UploadDepth(const float* reversed_z) {
    Impl& impl = *impl_;
    impl.backend.WaitForComposite();  // it may still read the depth
    const VkDeviceSize bytes = VkDeviceSize(impl.Width()) * impl.Height() * 4;
    if (!impl.depth_upload) {
        impl.depth_upload =
            Buffer(impl.context, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::kHostUpload);
    }
    std::memcpy(impl.depth_upload.GetMapped(), reversed_z, bytes);  // GL rows, stored as given
    SubmitAndWait(impl.context, impl.pool, [&](VkCommandBuffer cmd) {
        // Every texel is overwritten: the old contents may go.
        RecordOwnershipTransfer(cmd, impl.context, impl.depth, Transfer::kAcquire,
                                VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
        region.imageExtent = {impl.Width(), impl.Height(), 1};
        vkCmdCopyBufferToImage(cmd, impl.depth_upload.Get(), impl.depth.Get(),
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        RecordOwnershipTransfer(cmd, impl.context, impl.depth, Transfer::kRelease,
                                VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                                VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    });
}

void RenderCompositeToInterop(GaussianSplatBackend& backend, InteropTargets& targets,
                              const InteropCompositeRequest& request, InteropFrame& frame) {
    GaussianSplatVulkanBackend& vulkan = RequireVulkan(backend);
    if (&targets.impl_->backend != &vulkan) {
        core::ThrowError("Gaussian splat interop: the targets were made for another backend");
    }
    InteropSink sink(*targets.impl_, request, frame);
    frame.stats = vulkan.RenderComposite(sink);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
