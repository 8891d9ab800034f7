#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianCompositeStageRunner.h"
#include "open3d/core/Timer.h"

#include <chrono>
#include <cmath>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Image.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

Buffer UploadBuffer(const VulkanContext& context, const void* data, VkDeviceSize bytes,
                    VkBufferUsageFlags usage) {
    Buffer buffer(context, std::max<VkDeviceSize>(bytes, 16), usage, MemoryUsage::kHostUpload);
    if (bytes > 0) std::memcpy(buffer.GetMapped(), data, bytes);
    return buffer;
}

// An output image and the host buffer it is copied into after the frame.
struct Target {
    Image image;
    Buffer readback;
};

Target MakeTarget(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
                  uint32_t texel_bytes) {
    return {Image(context, width, height, format,
                  VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
            Buffer(context, VkDeviceSize(width) * height * texel_bytes,
                   VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::kHostReadback)};
}

void RecordReadback(VkCommandBuffer cmd, const Target& target) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {target.image.GetWidth(), target.image.GetHeight(), 1};
    vkCmdCopyImageToBuffer(cmd, target.image.Get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           target.readback.Get(), 1, &region);
}

template <typename T>
std::vector<T> Read(const Target& target) {
    std::vector<T> values(target.readback.GetSize() / sizeof(T));
    std::memcpy(values.data(), target.readback.GetMapped(), values.size() * sizeof(T));
    return values;
}

}  // namespace

GaussianCompositeStageRunner::GaussianCompositeStageRunner(const VulkanContext& context)
    : context_(context), pool_(context), composite_stage_(context), timestamps_(context) {}

CompositeStageReadback GaussianCompositeStageRunner::Run(const CompositeStageRunInputs& in) {
    const uint32_t w = in.width, h = in.height;
    if (w == 0 || h == 0)
        core::ThrowError("GaussianCompositeStageRunner: the image is {}x{}", w, h);
    if (in.entry_tiles.size() != in.entry_splats.size()) {
        core::ThrowError("GaussianCompositeStageRunner: {} entry tiles but {} entry splats",
                         in.entry_tiles.size(), in.entry_splats.size());
    }
    const bool has_scene_depth = !in.scene_depth.empty();
    if (has_scene_depth && in.scene_depth.size() != size_t(w) * h) {
        core::ThrowError("GaussianCompositeStageRunner: scene depth has {} values, {}x{} expected",
                         in.scene_depth.size(), w, h);
    }
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    const uint32_t num_entries = static_cast<uint32_t>(in.entry_tiles.size());
    // Read through its device address, as the geometry stage's records are.
    Buffer projected =
        UploadBuffer(context_, in.projected.data(), in.projected.size() * sizeof(in.projected[0]),
                     storage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
    Buffer keys = UploadBuffer(context_, in.entry_tiles.data(), num_entries * 4ull, storage);
    Buffer values = UploadBuffer(context_, in.entry_splats.data(), num_entries * 4ull, storage);
    // The count at uint index 1, as a producer's counter block would hold it.
    const uint32_t count_words[4] = {0xDEADBEEFu, num_entries, 0u, 0u};
    Buffer count = UploadBuffer(context_, count_words, sizeof(count_words), storage);
    const CompositeStageStorageRequirements need = GaussianCompositeStage::GetStorageRequirements();
    Buffer state(context_, GaussianCompositeStage::StateBytes(w, h), need.state_usage,
                 MemoryUsage::kDevice);

    const VkFormat color_format = ToVkFormat(in.color_format);
    const uint32_t color_texel = in.color_format == CompositeColorFormat::kRgba16f ? 8 : 16;
    Target color = MakeTarget(context_, w, h, color_format, color_texel);
    Target depth = MakeTarget(context_, w, h, need.scalar_format, 4);
    Target alpha = MakeTarget(context_, w, h, need.scalar_format, 4);
    Target median = MakeTarget(context_, w, h, need.scalar_format, 4);
    Target merged_normalized, merged_linear;
    if (in.depth_merge) {
        merged_normalized = MakeTarget(context_, w, h, need.normalized_depth_format, 2);
        merged_linear = MakeTarget(context_, w, h, need.scalar_format, 4);
    }
    Image scene_image;
    Buffer scene_upload;
    if (has_scene_depth) {
        scene_image = Image(context_, w, h, VK_FORMAT_D32_SFLOAT,
                            VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
        std::vector<float> rows(in.scene_depth.size());
        for (uint32_t y = 0; y < h; ++y) {
            const uint32_t row = in.scene_depth_flip_y ? h - 1 - y : y;
            std::memcpy(&rows[size_t(row) * w], &in.scene_depth[size_t(y) * w], w * 4);
        }
        scene_upload =
            UploadBuffer(context_, rows.data(), rows.size() * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    }
    SceneDepthTexture scene;
    scene.view = scene_image.GetView();
    scene.near_plane = in.scene_near;
    scene.flip_y = in.scene_depth_flip_y;
    const SceneDepthTexture* scene_used =
        has_scene_depth && !in.scene_depth_unused ? &scene : nullptr;

    CompositeStageInputs inputs;
    inputs.projected = projected.Range();
    inputs.entry_keys = keys.Range();
    inputs.entry_values = values.Range();
    inputs.entry_count = count.Range(4, 4);
    inputs.entry_capacity = num_entries;
    CompositeStageTargets targets;
    targets.width = w;
    targets.height = h;
    targets.color_format = in.color_format;
    targets.color = color.image.GetView();
    targets.depth = depth.image.GetView();
    targets.alpha = alpha.image.GetView();
    targets.median_depth = median.image.GetView();
    CompositeParams params;
    params.background = in.background;
    params.scene_depth = scene_used;
    params.max_workgroups = in.max_workgroups;

    std::vector<const Target*> outputs{&color, &depth, &alpha, &median};
    if (in.depth_merge) {
        outputs.push_back(&merged_normalized);
        outputs.push_back(&merged_linear);
    }
    CommandBuffer cmd = pool_.Allocate();
    cmd.Begin();
    VkCommandBuffer c = cmd.Get();
    timestamps_.RecordReset(c);
    for (const Target* target : outputs) {
        RecordImageBarrier(
            c, target->image.Get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
            VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    }
    if (has_scene_depth) RecordDepthTextureUpload(c, scene_image, scene_upload.Get());
    timestamps_.RecordBegin(c, TimedPass::kComposite);
    composite_stage_.RecordComposite(c, inputs, targets, state.Range(), params);
    timestamps_.RecordEnd(c, TimedPass::kComposite);
    if (in.depth_merge) {
        RecordMemoryBarrier(
            c, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
        DepthMergeImages images;
        images.width = w;
        images.height = h;
        images.splat_depth = depth.image.GetView();
        images.splat_alpha = alpha.image.GetView();
        images.normalized = merged_normalized.image.GetView();
        images.linear = merged_linear.image.GetView();
        DepthMergeParams merge = in.merge;
        merge.scene_depth = scene_used;
        timestamps_.RecordBegin(c, TimedPass::kDepthMerge);
        composite_stage_.RecordDepthMerge(c, images, merge);
        timestamps_.RecordEnd(c, TimedPass::kDepthMerge);
    }
    for (const Target* target : outputs) {
        RecordImageBarrier(
            c, target->image.Get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        RecordReadback(c, *target);
    }
    cmd.End();

    UniqueFence fence = CreateFence(context_);
    const auto start = std::chrono::steady_clock::now();
    Submit(context_, c, fence.Get());
    Wait(context_, fence.Get());

    CompositeStageReadback out;
    out.wall_ms = core::MillisecondsSince(start);
    const std::vector<double> ms = timestamps_.ReadMilliseconds();
    out.composite_ms = ms[static_cast<uint32_t>(TimedPass::kComposite)];
    out.merge_ms = ms[static_cast<uint32_t>(TimedPass::kDepthMerge)];
    if (in.color_format == CompositeColorFormat::kRgba16f) {
        const std::vector<uint16_t> halves = Read<uint16_t>(color);
        out.color.resize(halves.size());
        for (size_t i = 0; i < halves.size(); ++i) out.color[i] = HalfToFloat(halves[i]);
    } else {
        out.color = Read<float>(color);
    }
    out.depth = Read<float>(depth);
    out.alpha = Read<float>(alpha);
    out.median_depth = Read<float>(median);
    if (in.depth_merge) {
        out.merged_normalized = Read<uint16_t>(merged_normalized);
        out.merged_linear = Read<float>(merged_linear);
    }
    return out;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
