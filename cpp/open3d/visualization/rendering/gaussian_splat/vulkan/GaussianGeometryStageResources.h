// The GPU buffers geometry stage runs on: one packed scene (uploaded once) and one view's outputs
// and scratch, sized from GaussianGeometryStage::GetStorageRequirements. The backend and the test
// runner share it, so both allocate, upload and bind geometry stage the same way.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatLodPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStage.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

struct VulkanDeviceInfo;

/// A device-local storage buffer holding `bytes` of `data` (at least 16 bytes, zero-padded),
/// copied through a staging buffer and waited for; `extra_usage` is added to the storage and
/// transfer usages (VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT for what is read by address).
Buffer UploadStorageBuffer(const VulkanContext& context, const CommandPool& pool, const void* data,
                           VkDeviceSize bytes, VkBufferUsageFlags extra_usage = 0);
/// The same for `bytes` that `fill` writes into the (zeroed) staging memory.
Buffer UploadStorageBuffer(const VulkanContext& context, const CommandPool& pool,
                           VkDeviceSize bytes, const std::function<void(uint8_t*)>& fill,
                           VkBufferUsageFlags extra_usage = 0);

/// One view's geometry-stage outputs and scratch, sized for a splat count and an entry
/// capacity. The backend keeps one per frame slot, so frames in flight never share them.
class GeometryStageViewResources {
public:
    /// (Re)allocates every buffer for `num_splats` splats and `entry_capacity` entries, and,
    /// where the splats are a hierarchy's nodes (lod_inner has a value: its inner nodes),
    /// the cut's buffers.
    void Allocate(const VulkanContext& context, uint32_t num_splats, uint32_t entry_capacity,
                  std::optional<uint32_t> lod_inner = std::nullopt);
    /// Bindings for GaussianGeometryStage::Record.
    GeometryStageViewBuffers Buffers() const;
    uint32_t EntryCapacity() const { return entry_capacity_; }
    uint32_t NumSplats() const { return num_splats_; }
    std::optional<uint32_t> LodInner() const { return lod_inner_; }
    explicit operator bool() const { return static_cast<bool>(projected); }

    Buffer view_params, projected, counters, depth_keys, splat_indices, tile_counts, scan;
    Buffer entry_keys, entry_values, keys_alt, values_alt, histogram, sort_params;
    Buffer depth_sweep_state, tile_sweep_state;
    /// Empty without a hierarchy.
    Buffer lod_buckets, lod_histogram, lod_visibility, lod_group_counts, lod_list, lod_walk;

private:
    std::optional<uint32_t> lod_inner_;
    uint32_t num_splats_ = 0;
    uint32_t entry_capacity_ = 0;
};

class GeometryStageResources {
public:
    /// Uploads the packed attributes (a degree-0 scene gets a 16-byte SH placeholder: the
    /// binding must name a buffer) and keeps the packing's sizes.
    void UploadScene(const VulkanContext& context, const CommandPool& pool,
                     const PackedGaussianSplats& packed);
    /// Packs and uploads a valid cloud at `precision` (its SH degree), part by part: parts of
    /// kUploadPartSplats packed in parallel straight into one staging buffer of
    /// kUploadPartsPerSubmission parts, copied and waited for in turn. The host then holds
    /// the staging (about 160 MB), not a packed copy of the scene (152 bytes a splat, 22 GB
    /// for 144.5M splats). `mask` is the visibility mask (empty: every splat shown). The
    /// words are PackGaussianSplatAttrs's, bit for bit.
    void UploadSceneInParts(const VulkanContext& context, const CommandPool& pool,
                            const t::geometry::PointCloud& cloud, SplatPrecision precision,
                            const std::vector<uint32_t>& mask);
    static constexpr int64_t kUploadPartSplats = 65536;
    static constexpr int64_t kUploadPartsPerSubmission = 16;
    /// Zero-filled buffers for `capacity` splats packed like `like` (its words per splat,
    /// precision, degree and centre bounds), every splat hidden: a scene whose splats are
    /// written later (WriteSplats).
    void AllocateScene(const VulkanContext& context, const CommandPool& pool,
                       const PackedGaussianSplats& like, int64_t capacity);
    /// Writes each part (first splat, a valid cloud of the scene's SH degree) over splats
    /// [first, first + its splats) of the scene in one submission, and widens the centre
    /// bounds the depth range comes from to hold their centres (the streaming pool's page
    /// writes). The parts are packed in parallel straight into a staging buffer kept for the
    /// next call (a step's pages: no packed copy, no fresh host memory to fault in). The
    /// visibility mask is not touched.
    void WriteSplats(const VulkanContext& context, const CommandPool& pool,
                     const std::vector<std::pair<int64_t, const t::geometry::PointCloud*>>& parts);
    /// Uploads the nodes of the hierarchy the scene's splats are (GaussianSplatLodPacking.h);
    /// ClearLod forgets them (a plain scene).
    void UploadLod(const VulkanContext& context, const CommandPool& pool,
                   const PackedLodNodes& lod);
    void ClearLod();
    bool HasLod() const { return static_cast<bool>(lod_nodes); }
    uint32_t LodLeaves() const { return lod_leaves_; }
    std::optional<uint32_t> LodInner() const {
        return HasLod() ? std::optional<uint32_t>(lod_inner_) : std::nullopt;
    }
    /// Replaces the visibility mask ([ceil(N / 32)] words).
    void UploadVisibility(const VulkanContext& context, const CommandPool& pool,
                          const std::vector<uint32_t>& mask);
    /// (Re)allocates the per-view buffers for the scene's splats and `entry_capacity` entries.
    void AllocateView(const VulkanContext& context, uint32_t entry_capacity);

    /// Bindings of the uploaded scene and of the view buffers for GaussianGeometryStage::Record.
    GeometryStageSceneBuffers Scene() const;
    GeometryStageViewBuffers View() const;
    /// The view parameters of `camera` for this scene and view allocation, with the choices
    /// GaussianGeometryStage::Record picks its pipelines from.
    PackedView ViewParams(const camera::PinholeCamera& camera, const RenderConfig& config) const;
    /// The same for view buffers of `entry_capacity` entries (a frame slot's).
    PackedView ViewParams(const camera::PinholeCamera& camera, const RenderConfig& config,
                          uint32_t entry_capacity) const;

    /// The packing's sizes (its attribute vectors are empty).
    const PackedGaussianSplats& Layout() const { return layout_; }
    uint32_t EntryCapacity() const { return view_.EntryCapacity(); }
    bool HasView() const { return static_cast<bool>(view_); }
    const GeometryStageViewResources& ViewResources() const { return view_; }
    /// Bytes of the scene on the GPU: positions + shape + SH (if any) + visibility mask.
    uint64_t SceneBytes() const { return scene_bytes_; }

    // Scene.
    Buffer positions, shape, sh, visibility;
    /// For a hierarchy: shader::GaussianLodNode per splat, then (from an aligned offset) the
    /// inner nodes' children (PackedLodNodes::children).
    Buffer lod_nodes;

private:
    /// The packing's sizes of `like` for a scene of `num_splats`; drops the view buffers.
    void SetLayout(const PackedGaussianSplats& like, int64_t num_splats);

    uint32_t lod_leaves_ = 0, lod_inner_ = 0, lod_inner_levels_ = 0;
    VkDeviceSize lod_nodes_bytes_ = 0, lod_children_offset_ = 0, lod_children_bytes_ = 0;
    VkDeviceSize lod_previous_offset_ = 0;
    PackedGaussianSplats layout_;
    // WriteSplats' staging, as large as its largest call since the scene was made.
    Buffer write_staging_;
    // One view's outputs (projected splats, counters, sorted entries) and scratch.
    GeometryStageViewResources view_;
    uint64_t scene_bytes_ = 0;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
