#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianCompositeStage.h"

#include <algorithm>
#include <vector>

#include "GaussianSplatCompositeContract.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/ComputePipeline.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/EmbeddedShaders.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

using namespace shader;  // the contract's constants and structs

static_assert(kCompositeTileSize == static_cast<uint32_t>(rendering::kTileSize));
static_assert(kNoSplatId == kCompositeNoSplat);
// The GPU compares against the same float32 thresholds the reference widens to double.
static_assert(static_cast<double>(kCompositeMaxAlpha) == cpu::kMaxAlpha);
static_assert(static_cast<double>(kCompositeMinAlpha) == cpu::kMinAlpha);
static_assert(static_cast<double>(kCompositeMinTransmittance) == cpu::kMinTransmittance);

UniqueDescriptorSetLayout CreatePushLayout(const VulkanContext& context,
                                           const std::vector<VkDescriptorType>& types) {
    std::vector<VkDescriptorSetLayoutBinding> bindings(types.size());
    for (size_t i = 0; i < types.size(); ++i) {
        bindings[i].binding = static_cast<uint32_t>(i);
        bindings[i].descriptorType = types[i];
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo info = MakeInfo<VkDescriptorSetLayoutCreateInfo>(
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    info.bindingCount = static_cast<uint32_t>(bindings.size());
    info.pBindings = bindings.data();
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    CheckVk(vkCreateDescriptorSetLayout(context.GetDevice(), &info, nullptr, &layout),
            "vkCreateDescriptorSetLayout");
    return UniqueDescriptorSetLayout(context.GetDevice(), layout);
}

VkWriteDescriptorSet BufferWrite(uint32_t binding, const VkDescriptorBufferInfo* info) {
    VkWriteDescriptorSet write =
        MakeInfo<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
    write.dstBinding = binding;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    write.pBufferInfo = info;
    return write;
}

VkWriteDescriptorSet ImageWrite(uint32_t binding, VkDescriptorType type,
                                const VkDescriptorImageInfo* info) {
    VkWriteDescriptorSet write =
        MakeInfo<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
    write.dstBinding = binding;
    write.descriptorCount = 1;
    write.descriptorType = type;
    write.pImageInfo = info;
    return write;
}

VkDescriptorImageInfo StorageImage(VkImageView view) {
    return {VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL};
}

// Specialised on kSpecSceneDepth, kSpecCompositeDepth and kSpecColorBuffer. The depth merge
// declares only the first: Vulkan ignores a map entry whose ID the shader does not use.
UniquePipeline CreateSpecialised(const VulkanContext& context, VkPipelineLayout layout,
                                 std::span<const uint32_t> spirv, const char* name,
                                 bool scene_depth, uint32_t depth_outputs = 0u,
                                 bool color_buffer = false) {
    const std::array<uint32_t, 3> values{scene_depth ? 1u : 0u, depth_outputs,
                                         color_buffer ? 1u : 0u};
    const std::array<VkSpecializationMapEntry, 3> entries{
        {{kSpecSceneDepth, 0, sizeof(uint32_t)},
         {kSpecCompositeDepth, sizeof(uint32_t), sizeof(uint32_t)},
         {kSpecColorBuffer, 2 * sizeof(uint32_t), sizeof(uint32_t)}}};
    const VkSpecializationInfo specialization{static_cast<uint32_t>(entries.size()), entries.data(),
                                              sizeof(values), values.data()};
    return CreateComputePipeline(context, layout, spirv, name, &specialization);
}

void RequireView(VkImageView view, const char* what) {
    if (view == VK_NULL_HANDLE)
        core::ThrowError("GaussianCompositeStage: {} has no image view", what);
}

}  // namespace

VkFormat ToVkFormat(CompositeColorFormat format) {
    switch (format) {
        case CompositeColorFormat::kRgba16f:
            return VK_FORMAT_R16G16B16A16_SFLOAT;
        case CompositeColorFormat::kRgba8:
            return VK_FORMAT_R8G8B8A8_UNORM;
        default:
            return VK_FORMAT_R32G32B32A32_SFLOAT;
    }
}

GaussianCompositeStage::GaussianCompositeStage(const VulkanContext& context) : context_(context) {
    const VkDescriptorType kBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    const VkDescriptorType kStorage = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    const VkDescriptorType kSampled = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    std::vector<VkDescriptorType> composite(kCompositeNumBindings, kStorage);
    composite[kCompositeEntryKeysBinding] = kBuffer;
    composite[kCompositeEntryValuesBinding] = kBuffer;
    composite[kCompositeCountBinding] = kBuffer;
    composite[kCompositeStateBinding] = kBuffer;
    composite[kCompositeSceneDepthBinding] = kSampled;
    composite[kCompositeColorBufferBinding] = kBuffer;
    composite_set_layout_ = CreatePushLayout(context, composite);
    composite_layout_ = CreatePipelineLayout(context, composite_set_layout_.Get(),
                                             sizeof(GaussianCompositePushConstants));
    tile_ranges_ = CreateComputePipeline(context, composite_layout_.Get(),
                                         spirv::kGaussianTileRanges, "gaussian_tile_ranges");
    std::vector<VkDescriptorType> merge(kDepthMergeNumBindings, kStorage);
    merge[kDepthMergeSceneDepthBinding] = kSampled;
    merge_set_layout_ = CreatePushLayout(context, merge);
    merge_layout_ = CreatePipelineLayout(context, merge_set_layout_.Get(),
                                         sizeof(GaussianDepthMergePushConstants));
    std::vector<VkDescriptorType> blend(kBlendOverNumBindings, kStorage);
    blend[kBlendOverMeshColorBinding] = kSampled;
    blend[kBlendOverOutputBinding] = kBuffer;
    blend_set_layout_ = CreatePushLayout(context, blend);
    blend_layout_ = CreatePipelineLayout(context, blend_set_layout_.Get(),
                                         sizeof(GaussianBlendOverPushConstants));
    placeholder_depth_ = Image(context, 1, 1, VK_FORMAT_R32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT);
    placeholder_splat_id_ =
        Image(context, 1, 1, kSplatIdFormat, GetStorageRequirements().image_usage);
}

CompositeStageStorageRequirements GaussianCompositeStage::GetStorageRequirements() {
    return CompositeStageStorageRequirements{};
}

VkDeviceSize GaussianCompositeStage::StateBytes(uint32_t width, uint32_t height) {
    const uint64_t tiles_x = (uint64_t(width) + kCompositeTileSize - 1) / kCompositeTileSize;
    const uint64_t tiles_y = (uint64_t(height) + kCompositeTileSize - 1) / kCompositeTileSize;
    return sizeof(GaussianCompositeState) + sizeof(uint32_t) * 2 * tiles_x * tiles_y;
}

bool GaussianCompositeStage::ColorBufferFits(uint32_t width, uint32_t height,
                                             VkDeviceSize offset) const {
    const VulkanDeviceInfo& info = context_.GetDeviceInfo();
    const uint64_t bytes = uint64_t(width) * height * 16;
    return bytes <= info.max_storage_buffer_range &&
           offset % info.min_storage_buffer_offset_alignment == 0;
}

VkPipeline GaussianCompositeStage::GetCompositePipeline(CompositeColorFormat format,
                                                        const CompositeParams& params,
                                                        bool color_buffer) {
    const bool scene_depth = params.scene_depth != nullptr;
    const uint32_t depth_outputs = (params.expected_depth ? kCompositeExpectedDepthBit : 0u) |
                                   (params.median_depth ? kCompositeMedianDepthBit : 0u) |
                                   (params.splat_id ? kCompositeSplatIdBit : 0u);
    static_assert(kCompositeExpectedDepthBit == 1u && kCompositeMedianDepthBit == 2u &&
                  kCompositeSplatIdBit == 4u);
    const uint32_t format_index = static_cast<uint32_t>(format);
    UniquePipeline& pipeline = composite_[(color_buffer ? 48u : 0u) + format_index * 16u +
                                          (scene_depth ? 8u : 0u) + depth_outputs];
    if (!pipeline) {
        std::span<const uint32_t> code = spirv::kGaussianComposite;
        const char* name = "gaussian_composite";
        if (format == CompositeColorFormat::kRgba16f) {
            code = spirv::kGaussianCompositeRgba16f;
            name = "gaussian_composite_rgba16f";
        } else if (format == CompositeColorFormat::kRgba8) {
            code = spirv::kGaussianCompositeRgba8;
            name = "gaussian_composite_rgba8";
        }
        pipeline = CreateSpecialised(context_, composite_layout_.Get(), code, name, scene_depth,
                                     depth_outputs, color_buffer);
    }
    return pipeline.Get();
}

VkPipeline GaussianCompositeStage::GetDepthMergePipeline(bool scene_depth) {
    UniquePipeline& pipeline = merge_[scene_depth ? 1 : 0];
    if (!pipeline) {
        pipeline = CreateSpecialised(context_, merge_layout_.Get(), spirv::kGaussianDepthMerge,
                                     "gaussian_depth_merge", scene_depth);
    }
    return pipeline.Get();
}

VkDescriptorImageInfo GaussianCompositeStage::SceneDepthDescriptor(
    VkCommandBuffer cmd, const SceneDepthTexture* scene_depth) const {
    if (scene_depth) {
        RequireView(scene_depth->view, "scene_depth");
        return {VK_NULL_HANDLE, scene_depth->view, scene_depth->layout};
    }
    // The pipeline specialised without scene depth never reads the binding, but a statically
    // used binding must still hold a valid descriptor. UNDEFINED -> read-only each time
    // (its contents are never read); the barrier also orders it after earlier dispatches.
    RecordImageBarrier(cmd, placeholder_depth_.Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                       VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_NONE,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    return {VK_NULL_HANDLE, placeholder_depth_.GetView(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
}

VkDescriptorImageInfo GaussianCompositeStage::SplatIdDescriptor(VkCommandBuffer cmd,
                                                                VkImageView splat_id) const {
    if (splat_id != VK_NULL_HANDLE) return StorageImage(splat_id);
    // As for the scene depth: never written without kCompositeSplatIdBit, but the binding is
    // statically used, and the validation layer counts a write-only binding as written by
    // every dispatch that binds it. UNDEFINED -> GENERAL each time, after those "writes" (an
    // earlier composite of the same command buffer).
    RecordImageBarrier(cmd, placeholder_splat_id_.Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                       VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    return StorageImage(placeholder_splat_id_.GetView());
}

void GaussianCompositeStage::RecordComposite(VkCommandBuffer cmd,
                                             const CompositeStageInputs& inputs,
                                             const CompositeStageTargets& targets,
                                             const BufferRange& state,
                                             const CompositeParams& params) {
    if (targets.width == 0 || targets.height == 0) {
        core::ThrowError("GaussianCompositeStage: the image is {}x{}", targets.width,
                         targets.height);
    }
    RequireView(targets.color, "color");
    RequireView(targets.depth, "depth");
    RequireView(targets.alpha, "alpha");
    RequireView(targets.median_depth, "median_depth");
    if (params.splat_id) RequireView(targets.splat_id, "splat_id");
    const VkDeviceSize alignment = context_.GetDeviceInfo().min_storage_buffer_offset_alignment;
    for (const BufferRange* range : {&inputs.entry_keys, &inputs.entry_values, &state}) {
        if (range->buffer == VK_NULL_HANDLE || range->offset % alignment != 0) {
            core::ThrowError(
                "GaussianCompositeStage: every input buffer needs a buffer and an offset that is a "
                "multiple of minStorageBufferOffsetAlignment {}",
                alignment);
        }
    }
    const std::array<uint32_t, 2> projected =
        DeviceAddressWords(inputs.projected, "GaussianCompositeStage: the projected records");
    if (inputs.entry_count.buffer == VK_NULL_HANDLE || inputs.entry_count.offset % 4 != 0) {
        core::ThrowError(
            "GaussianCompositeStage: entry_count needs a buffer and a 4-byte aligned offset");
    }
    const bool color_buffer = targets.color_buffer.buffer != VK_NULL_HANDLE;
    const VkDeviceSize color_buffer_bytes = VkDeviceSize(targets.width) * targets.height * 16;
    if (color_buffer) {
        if (targets.color_format != CompositeColorFormat::kRgba32f) {
            core::ThrowError("GaussianCompositeStage: a colour buffer takes RGBA32F only");
        }
        if (!ColorBufferFits(targets.width, targets.height, targets.color_buffer.offset) ||
            (targets.color_buffer.size != VK_WHOLE_SIZE &&
             targets.color_buffer.size < color_buffer_bytes)) {
            core::ThrowError(
                "GaussianCompositeStage: the colour buffer range (offset {}, {} bytes) cannot "
                "hold a {}x{} RGBA32F image on this device",
                targets.color_buffer.offset, targets.color_buffer.size, targets.width,
                targets.height);
        }
    }
    const VkDeviceSize state_bytes = StateBytes(targets.width, targets.height);
    if (state.size != VK_WHOLE_SIZE && state.size < state_bytes) {
        core::ThrowError("GaussianCompositeStage: state holds {} bytes, a {}x{} image needs {}",
                         state.size, targets.width, targets.height, state_bytes);
    }

    const uint32_t tiles_x = (targets.width + kCompositeTileSize - 1) / kCompositeTileSize;
    const uint32_t tiles_y = (targets.height + kCompositeTileSize - 1) / kCompositeTileSize;
    const uint64_t num_tiles = uint64_t(tiles_x) * tiles_y;
    // CPU devices (lavapipe) get one workgroup per tile: llvmpipe caps the loop iterations
    // of an invocation (see gaussian_composite.glsl), so one workgroup must not do many
    // tiles; GPUs get a fixed grid whose workgroups steal tiles.
    const bool cpu_device = context_.GetDeviceInfo().type == "CPU";
    const uint32_t max_workgroups = params.max_workgroups > 0 ? params.max_workgroups
                                    : cpu_device              ? kMaxWorkgroupsPerDispatch
                                                              : kDefaultMaxWorkgroups;
    const uint32_t workgroups = static_cast<uint32_t>(
        std::min<uint64_t>(num_tiles, std::min(max_workgroups, kMaxWorkgroupsPerDispatch)));

    // Work stealing starts from tile 0 in every dispatch; tiles without entries keep [0, 0).
    // Ranges left by the geometry stage's bins were written by its compute passes, which the
    // fill of the tile counter (the same binding to them) must follow.
    if (inputs.state_zeroed && !inputs.ranges_written) {
        core::ThrowError("GaussianCompositeStage: a zeroed state needs ranges_written");
    }
    if (!inputs.state_zeroed) {
        if (inputs.ranges_written) {
            RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        }
        vkCmdFillBuffer(cmd, state.buffer, state.offset,
                        inputs.ranges_written ? sizeof(GaussianCompositeState) : state_bytes, 0u);
        RecordMemoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    }

    // The count may sit at any 4-byte offset: bind from the aligned offset below it.
    const VkDeviceSize count_offset =
        inputs.entry_count.offset - inputs.entry_count.offset % alignment;
    GaussianCompositePushConstants push{};
    push.width = targets.width;
    push.height = targets.height;
    push.tiles_x = tiles_x;
    push.tiles_y = tiles_y;
    push.count_index = static_cast<uint32_t>((inputs.entry_count.offset - count_offset) / 4);
    push.entry_capacity = inputs.entry_capacity;
    push.scene_depth_flip_y = params.scene_depth && params.scene_depth->flip_y ? 1u : 0u;
    push.background = {params.background[0], params.background[1], params.background[2]};
    push.scene_near = params.scene_depth ? params.scene_depth->near_plane : 0.f;
    push.projected_lo = projected[0];
    push.projected_hi = projected[1];

    const VkDeviceSize entry_bytes = VkDeviceSize(std::max(inputs.entry_capacity, 1u)) * 4;
    // Without a colour buffer the binding is never written (kSpecColorBuffer 0) but must hold
    // a valid descriptor: the state buffer stands in.
    const VkDescriptorBufferInfo color_buffer_info =
        color_buffer ? VkDescriptorBufferInfo{targets.color_buffer.buffer,
                                              targets.color_buffer.offset, color_buffer_bytes}
                     : VkDescriptorBufferInfo{state.buffer, state.offset, state_bytes};
    const std::array<VkDescriptorBufferInfo, 5> buffers{{
        {inputs.entry_keys.buffer, inputs.entry_keys.offset, entry_bytes},
        {inputs.entry_values.buffer, inputs.entry_values.offset, entry_bytes},
        {inputs.entry_count.buffer, count_offset, VK_WHOLE_SIZE},
        {state.buffer, state.offset, state_bytes},
        color_buffer_info,
    }};
    const std::array<VkDescriptorImageInfo, 6> images{{
        StorageImage(targets.color),
        StorageImage(targets.depth),
        StorageImage(targets.alpha),
        StorageImage(targets.median_depth),
        SceneDepthDescriptor(cmd, params.scene_depth),
        SplatIdDescriptor(cmd, params.splat_id ? targets.splat_id : VK_NULL_HANDLE),
    }};
    const std::array<VkWriteDescriptorSet, kCompositeNumBindings> writes{{
        BufferWrite(kCompositeEntryKeysBinding, &buffers[0]),
        BufferWrite(kCompositeEntryValuesBinding, &buffers[1]),
        BufferWrite(kCompositeCountBinding, &buffers[2]),
        BufferWrite(kCompositeStateBinding, &buffers[3]),
        ImageWrite(kCompositeColorBinding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, &images[0]),
        ImageWrite(kCompositeDepthBinding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, &images[1]),
        ImageWrite(kCompositeAlphaBinding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, &images[2]),
        ImageWrite(kCompositeMedianDepthBinding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, &images[3]),
        ImageWrite(kCompositeSceneDepthBinding, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, &images[4]),
        BufferWrite(kCompositeColorBufferBinding, &buffers[4]),
        ImageWrite(kCompositeSplatIdBinding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, &images[5]),
    }};
    // Both pipelines share the layout: descriptors and push constants are set once.
    context_.GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, composite_layout_.Get(),
                                       0, kCompositeNumBindings, writes.data());
    vkCmdPushConstants(cmd, composite_layout_.Get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push),
                       &push);
    // Tile ranges: a grid-stride pass over the entries, at most kMaxRangeWorkgroups wide.
    constexpr uint64_t kMaxRangeWorkgroups = 2048;
    const uint64_t range_workgroups = std::min<uint64_t>(
        kMaxRangeWorkgroups,
        (uint64_t(std::max(inputs.entry_capacity, 1u)) + kCompositeWorkgroupSize - 1) /
            kCompositeWorkgroupSize);
    if (!inputs.ranges_written) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, tile_ranges_.Get());
        RecordDispatch(cmd, static_cast<uint32_t>(range_workgroups), 1, 1);
        RecordMemoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    }
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE,
                      GetCompositePipeline(targets.color_format, params, color_buffer));
    RecordDispatch(cmd, workgroups, 1, 1);
}

void GaussianCompositeStage::RecordDepthMerge(VkCommandBuffer cmd, const DepthMergeImages& images,
                                              const DepthMergeParams& params) {
    if (images.width == 0 || images.height == 0) {
        core::ThrowError("GaussianCompositeStage: the image is {}x{}", images.width, images.height);
    }
    RequireView(images.splat_depth, "splat_depth");
    RequireView(images.splat_alpha, "splat_alpha");
    RequireView(images.normalized, "normalized");
    RequireView(images.linear, "linear");
    if (!(params.far > params.near)) {
        core::ThrowError("GaussianCompositeStage: depth merge range [{}, {}] is empty", params.near,
                         params.far);
    }
    GaussianDepthMergePushConstants push{};
    push.width = images.width;
    push.height = images.height;
    push.scene_depth_flip_y = params.scene_depth && params.scene_depth->flip_y ? 1u : 0u;
    push.near_plane = params.near;
    push.far_plane = params.far;
    push.scene_near = params.scene_depth ? params.scene_depth->near_plane : 0.f;
    push.min_alpha = params.min_alpha;
    const std::array<VkDescriptorImageInfo, kDepthMergeNumBindings> infos{{
        StorageImage(images.splat_depth),
        StorageImage(images.splat_alpha),
        SceneDepthDescriptor(cmd, params.scene_depth),
        StorageImage(images.normalized),
        StorageImage(images.linear),
    }};
    std::array<VkWriteDescriptorSet, kDepthMergeNumBindings> writes{};
    for (uint32_t i = 0; i < kDepthMergeNumBindings; ++i) {
        writes[i] = ImageWrite(i,
                               i == kDepthMergeSceneDepthBinding ? VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE
                                                                 : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
                               &infos[i]);
    }
    RecordPerPixelPass(cmd, GetDepthMergePipeline(params.scene_depth != nullptr),
                       merge_layout_.Get(), writes, &push, sizeof(push), images.width,
                       images.height, kDepthMergeWorkgroupSize);
}

void GaussianCompositeStage::RecordBlendOver(VkCommandBuffer cmd, const BlendOverImages& images) {
    if (images.width == 0 || images.height == 0) {
        core::ThrowError("GaussianCompositeStage: the image is {}x{}", images.width, images.height);
    }
    RequireView(images.splat_color, "splat_color");
    RequireView(images.mesh_color, "mesh_color");
    if (images.output == VK_NULL_HANDLE) {
        core::ThrowError("GaussianCompositeStage: the blend has no output buffer");
    }
    if (!blend_) {
        blend_ = CreateComputePipeline(context_, blend_layout_.Get(), spirv::kGaussianBlendOver,
                                       "gaussian_blend_over");
    }
    GaussianBlendOverPushConstants push{};
    push.width = images.width;
    push.height = images.height;
    push.mesh_flip_y = images.mesh_flip_y ? 1u : 0u;
    VkDescriptorImageInfo mesh{};
    mesh.imageView = images.mesh_color;
    mesh.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
    const VkDescriptorImageInfo splat = StorageImage(images.splat_color);
    const VkDescriptorBufferInfo output{images.output, 0,
                                        VkDeviceSize(images.width) * images.height * 4};
    std::array<VkWriteDescriptorSet, kBlendOverNumBindings> writes{};
    writes[kBlendOverSplatColorBinding] =
        ImageWrite(kBlendOverSplatColorBinding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, &splat);
    writes[kBlendOverMeshColorBinding] =
        ImageWrite(kBlendOverMeshColorBinding, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, &mesh);
    writes[kBlendOverOutputBinding] = BufferWrite(kBlendOverOutputBinding, &output);
    RecordPerPixelPass(cmd, blend_.Get(), blend_layout_.Get(), writes, &push, sizeof(push),
                       images.width, images.height, kBlendOverWorkgroupSize);
}

void GaussianCompositeStage::RecordPerPixelPass(VkCommandBuffer cmd, VkPipeline pipeline,
                                                VkPipelineLayout layout,
                                                std::span<const VkWriteDescriptorSet> writes,
                                                const void* push, uint32_t push_bytes,
                                                uint32_t width, uint32_t height,
                                                uint32_t workgroup_size) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    context_.GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0,
                                       static_cast<uint32_t>(writes.size()), writes.data());
    vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes, push);
    RecordDispatch(cmd, (width + workgroup_size - 1) / workgroup_size,
                   (height + workgroup_size - 1) / workgroup_size, 1);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
