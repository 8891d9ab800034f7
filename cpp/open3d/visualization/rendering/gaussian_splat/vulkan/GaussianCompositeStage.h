// Composite stage of the Vulkan pipeline as a recorder (docs/DESIGN.md "Code rules"): the
// per-tile composite of the tile-sorted entries that the geometry stage (or a test) produced,
// and the depth merge for depth readback. The caller owns every buffer and image; Record*()
// only records commands (no allocation, no submit). Design and images: docs/vulkan.md
// "Composite stage"; measured errors and times: docs/perf/.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Image.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

/// Format of the composite's colour image (one SPIR-V module each: storage image formats
/// are declared in the shader).
enum class CompositeColorFormat {
    /// VK_FORMAT_R32G32B32A32_SFLOAT: headless readback at full accuracy.
    kRgba32f,
    /// VK_FORMAT_R16G16B16A16_SFLOAT: the Filament overlay. Its quantisation alone costs
    /// about 77 dB PSNR against the float32 result, below the 80 dB accuracy target.
    kRgba16f,
    /// VK_FORMAT_R8G8B8A8_UNORM: batched rendering for 8-bit images (a quarter of the bytes
    /// to read back; the conversion is the device's float-to-unorm rounding).
    kRgba8,
};

VkFormat ToVkFormat(CompositeColorFormat format);

/// The ID image's format: the dominant splat's index, kCompositeNoSplat (-1 as int32) where
/// no splat blends.
inline constexpr VkFormat kSplatIdFormat = VK_FORMAT_R32_UINT;
/// The ID image where no splat blends (== shader::kCompositeNoSplat).
inline constexpr uint32_t kNoSplatId = 0xFFFFFFFFu;

/// Formats and usages of what the caller allocates for composite stage.
struct CompositeStageStorageRequirements {
    /// Usage of the composite's state buffer (its size: GaussianCompositeStage::StateBytes).
    VkBufferUsageFlags state_usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    /// Expected depth, alpha, median depth and the merged linear depth.
    VkFormat scalar_format = VK_FORMAT_R32_SFLOAT;
    /// The merged depth normalised to [0, 65535].
    VkFormat normalized_depth_format = VK_FORMAT_R16_UINT;
    /// Every output image needs this usage (add TRANSFER_SRC to read it back, SAMPLED to
    /// draw it); the recorder expects them in VK_IMAGE_LAYOUT_GENERAL.
    VkImageUsageFlags image_usage = VK_IMAGE_USAGE_STORAGE_BIT;
};

/// Geometry stage's results that the composite reads (all written on the GPU).
struct CompositeStageInputs {
    /// shader::GaussianProjectedSplat [N], indexed by splat; read through its device address
    /// (BufferRange::address), so it may be larger than one storage binding.
    BufferRange projected;
    BufferRange entry_keys;    ///< uint32 [capacity]: tile index, ascending
    BufferRange entry_values;  ///< uint32 [capacity]: splat index, front to back per tile
    /// uint32 entry count (any 4-byte aligned offset), e.g.
    /// GaussianGeometryStageCounters::entry_count. Counts above `entry_capacity` are clamped.
    BufferRange entry_count;
    uint32_t entry_capacity = 0;
    /// The geometry stage's per-tile bins left every tile's [begin, end) in the state
    /// buffer passed to RecordComposite (GeometryStageViewBuffers::tile_ranges): the
    /// ranges pass is skipped and only the tile counter is zeroed.
    bool ranges_written = false;
    /// With ranges_written: the geometry stage recorded just before this composite, in the
    /// same recording, also zeroed the state's header (the tile counter; the per-tile bins
    /// and the chained frame do, GaussianGeometryStage::WritesTileRanges), so the composite
    /// records no fill and no barriers of its own; the caller's barrier after the geometry
    /// stage orders it. Not for a composite that may run again on the same geometry stage.
    bool state_zeroed = false;
};

/// The composite's outputs, width x height, in VK_IMAGE_LAYOUT_GENERAL.
struct CompositeStageTargets {
    uint32_t width = 0;
    uint32_t height = 0;
    CompositeColorFormat color_format = CompositeColorFormat::kRgba32f;
    /// rgb = C + T * background (premultiplied when the background is black), a = 1 - T.
    VkImageView color = VK_NULL_HANDLE;
    /// R32F sum(alpha_i T_i z_i) / (1 - T), view-space z; 0 where no splat contributes.
    /// Written only with CompositeParams::expected_depth (the view must be valid anyway).
    VkImageView depth = VK_NULL_HANDLE;
    /// R32F accumulated alpha 1 - T (what the depth merge reads), written like `depth`.
    VkImageView alpha = VK_NULL_HANDLE;
    /// R32F view z of the splat that brings 1 - T to >= 0.5; 0 where it never gets there.
    /// Written only with CompositeParams::median_depth.
    VkImageView median_depth = VK_NULL_HANDLE;
    /// R32_UINT (kSplatIdFormat) splat index of the largest alpha_i T_i at the pixel (the
    /// first of equal ones), kCompositeNoSplat where nothing blends. Needed only with
    /// CompositeParams::splat_id.
    VkImageView splat_id = VK_NULL_HANDLE;
    /// Optional, RGBA32F only: the colour goes here instead of `color` (which must still be
    /// a valid view; it is left as it was): width x height vec4 row-major, the floats the
    /// image would hold. A storage buffer range at a minStorageBufferOffsetAlignment offset,
    /// at most maxStorageBufferRange bytes (ColorBufferFits). Batches use it to skip the
    /// image-to-buffer copy. Synchronisation as for the images (COMPUTE_SHADER storage writes).
    BufferRange color_buffer;
};

/// A sampled depth texture in Filament's convention: reversed-Z with an infinite far plane,
/// d = near / z_view, cleared to 0 where nothing was drawn (D32_SFLOAT or R32_SFLOAT).
struct SceneDepthTexture {
    VkImageView view = VK_NULL_HANDLE;
    VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    /// The near plane of the projection that wrote it: z_view = near_plane / d.
    float near_plane = 0.1f;
    /// True when row 0 is the bottom row (a texture shared with GL / Filament).
    bool flip_y = false;
};

struct CompositeParams {
    std::array<float, 3> background{0.f, 0.f, 0.f};
    /// Scene depth to test each splat against (a splat farther than the scene at a pixel is
    /// skipped), or nullptr: then the pipeline specialised without it runs and reads no depth.
    const SceneDepthTexture* scene_depth = nullptr;
    /// The depth images to write (CompositeStageTargets); each is a pipeline specialisation, and
    /// one not asked for costs nothing per blended splat (the images it leaves keep old values).
    bool expected_depth = true;  ///< expected depth and alpha
    bool median_depth = true;
    /// The ID image (CompositeStageTargets::splat_id), a specialisation like the depths.
    bool splat_id = false;
    /// Workgroups of the grid (workgroup i does tile i, then steals tiles from a counter):
    /// 0 = min(tiles, kDefaultMaxWorkgroups) on GPUs, one per tile on CPU devices.
    uint32_t max_workgroups = 0;
};

struct DepthMergeParams {
    /// Normalisation of the R16UI output: u = round(65535 * clamp((z - near) / (far - near))).
    float near = 0.2f;
    float far = 100.0f;
    /// The splat depth counts where the accumulated alpha is > 0 and >= min_alpha.
    float min_alpha = 0.5f;
    const SceneDepthTexture* scene_depth = nullptr;
};

/// The merge's images (VK_IMAGE_LAYOUT_GENERAL): inputs are the composite's depth (or
/// median depth) and alpha images.
struct DepthMergeImages {
    uint32_t width = 0;
    uint32_t height = 0;
    VkImageView splat_depth = VK_NULL_HANDLE;  ///< R32F view z
    VkImageView splat_alpha = VK_NULL_HANDLE;  ///< R32F 1 - T
    VkImageView normalized = VK_NULL_HANDLE;   ///< R16UI out; 65535 where nothing is
    VkImageView linear = VK_NULL_HANDLE;       ///< R32F out: merged view z, 0 where nothing is
};

/// The blend over the mesh colour: the composite's colour (RGBA16F, GENERAL) over an RGBA8
/// mesh colour (sampled, GENERAL), into a storage buffer of width * height packed RGBA8
/// words, top row first.
struct BlendOverImages {
    uint32_t width = 0;
    uint32_t height = 0;
    VkImageView splat_color = VK_NULL_HANDLE;
    VkImageView mesh_color = VK_NULL_HANDLE;
    bool mesh_flip_y = true;  ///< the mesh colour's row 0 is the bottom row (GL)
    VkBuffer output = VK_NULL_HANDLE;
};

class GaussianCompositeStage {
public:
    /// Workgroups of the default work-stealing grid (enough to fill a large GPU; a CPU
    /// device runs them on its threads).
    static constexpr uint32_t kDefaultMaxWorkgroups = 1024;
    /// maxComputeWorkGroupCount[0] guaranteed by Vulkan.
    static constexpr uint32_t kMaxWorkgroupsPerDispatch = 65535;

    /// Creates the layouts and a 1x1 placeholder depth texture (bound when no scene depth
    /// is given). Pipelines are made on first use per colour format / scene-depth variant.
    explicit GaussianCompositeStage(const VulkanContext& context);

    static CompositeStageStorageRequirements GetStorageRequirements();
    /// Bytes of the composite's state for a width x height image: shader::GaussianCompositeState
    /// (the work-stealing tile counter) and each tile's entry range, both rewritten per frame.
    static VkDeviceSize StateBytes(uint32_t width, uint32_t height);
    /// Whether CompositeStageTargets::color_buffer can take a width x height RGBA32F image at
    /// `offset` on this device (the binding's range limit and offset alignment).
    bool ColorBufferFits(uint32_t width, uint32_t height, VkDeviceSize offset) const;

    /// Records the composite: zero `state` (vkCmdFillBuffer, StateBytes(width, height)), find
    /// each tile's range of the sorted entries (gaussian_tile_ranges.comp), then one dispatch
    /// of a fixed grid of workgroups that take tiles until all ceil(W/16) x ceil(H/16) are done.
    ///
    /// Synchronisation: before, the caller makes the inputs (and scene depth) visible to
    /// COMPUTE_SHADER reads, has the targets in GENERAL layout, and orders earlier uses of
    /// `state`; after, the images are COMPUTE_SHADER storage writes for the caller to barrier.
    void RecordComposite(VkCommandBuffer cmd, const CompositeStageInputs& inputs,
                         const CompositeStageTargets& targets, const BufferRange& state,
                         const CompositeParams& params);

    /// Records the depth merge (16x16 pixels per workgroup). Synchronisation as above: the
    /// composite's writes must be made visible to COMPUTE_SHADER reads before.
    void RecordDepthMerge(VkCommandBuffer cmd, const DepthMergeImages& images,
                          const DepthMergeParams& params);
    /// Records the blend over the mesh colour (gaussian_blend_over.comp). Synchronisation as
    /// above; after, the output buffer is a COMPUTE_SHADER storage write.
    void RecordBlendOver(VkCommandBuffer cmd, const BlendOverImages& images);

private:
    VkPipeline GetCompositePipeline(CompositeColorFormat format, const CompositeParams& params,
                                    bool color_buffer);
    VkPipeline GetDepthMergePipeline(bool scene_depth);
    // The per-pixel passes (depth merge, blend): bind, push descriptors and constants, and
    // dispatch workgroup_size x workgroup_size pixels per workgroup.
    void RecordPerPixelPass(VkCommandBuffer cmd, VkPipeline pipeline, VkPipelineLayout layout,
                            std::span<const VkWriteDescriptorSet> writes, const void* push,
                            uint32_t push_bytes, uint32_t width, uint32_t height,
                            uint32_t workgroup_size) const;
    // The view and layout to bind for `scene_depth`; records the placeholder's transition
    // when it stands in.
    VkDescriptorImageInfo SceneDepthDescriptor(VkCommandBuffer cmd,
                                               const SceneDepthTexture* scene_depth) const;

    const VulkanContext& context_;
    UniqueDescriptorSetLayout composite_set_layout_;
    UniquePipelineLayout composite_layout_;
    UniqueDescriptorSetLayout merge_set_layout_;
    UniquePipelineLayout merge_layout_;
    UniqueDescriptorSetLayout blend_set_layout_;
    UniquePipelineLayout blend_layout_;
    UniquePipeline blend_;  // made on first use
    UniquePipeline tile_ranges_;
    VkDescriptorImageInfo SplatIdDescriptor(VkCommandBuffer cmd, VkImageView splat_id) const;

    // [colour buffer][format][scene depth][splat ID][expected depth][median depth]
    std::array<UniquePipeline, 96> composite_;  // buffer * 48 + format * 16 + depth * 8 + outputs
    std::array<UniquePipeline, 2> merge_;       // [scene depth]
    Image placeholder_depth_;
    Image placeholder_splat_id_;  // bound when no ID image is asked for
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
