// Geometry stage of the Vulkan pipeline as a recorder (docs/DESIGN.md "Code rules"): project
// the splats, order the visible ones by exact float32 depth (ties by splat index), emit one entry
// per touched tile in that order and stably sort the entries by tile. The seed's packed
// 32-bit (tile, truncated depth) key is an option (RenderConfig::sort_mode). The caller
// allocates from GetStorageRequirements; Record() only records commands (no allocation,
// no submit). Pass sequence and buffers: docs/vulkan.md "Geometry stage".
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <map>

#include "GaussianSplatTileListContract.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianLodCut.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GpuTimestamps.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/RadixSort.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

/// Bytes of every buffer geometry stage needs for up to `num_splats` splats and
/// `entry_capacity` tile entries. All are storage buffers; `counters` is also read by
/// indirect dispatches and copied (TRANSFER_SRC / TRANSFER_DST), `view_params` is written
/// with vkCmdUpdateBuffer (TRANSFER_DST).
struct GeometryStageStorageRequirements {
    VkDeviceSize view_params_bytes = 0;    ///< shader::GaussianViewParams
    VkDeviceSize projected_bytes = 0;      ///< shader::GaussianProjectedSplat [N]
    VkDeviceSize counters_bytes = 0;       ///< shader::GaussianGeometryStageCounters
    VkDeviceSize depth_keys_bytes = 0;     ///< uint32 [N]
    VkDeviceSize splat_indices_bytes = 0;  ///< uint32 [N]
    VkDeviceSize tile_counts_bytes = 0;    ///< uint32 [N]
    VkDeviceSize scan_bytes = 0;           ///< uint32 [N + block sums of every level]
    VkDeviceSize entry_keys_bytes = 0;     ///< uint32 [entry_capacity]
    VkDeviceSize entry_values_bytes = 0;   ///< uint32 [entry_capacity]
    /// One scratch set shared by the three sorts (they run one after the other).
    RadixSortStorageRequirements sort;
    uint32_t num_scan_levels = 1;  ///< levels of the tile-count scan
    std::array<uint32_t, shader::kScanMaxLevels> scan_level_base{};  ///< uint offsets
    VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBufferUsageFlags counters_usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
        VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBufferUsageFlags view_params_usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
};

/// The packed scene (PackGaussianSplatAttrs) on the GPU.
struct GeometryStageSceneBuffers {
    BufferRange positions;  ///< vec4 [N]
    BufferRange shape;      ///< uint32 [N, shape words]
    /// uint32 [N, sh words]. At SH degree 0 nothing is read from it; any small buffer
    /// serves (the binding must still name a valid buffer).
    BufferRange sh;
    BufferRange visibility;  ///< uint32 [ceil(N / 32)]; unread for a hierarchy (lod)
    uint32_t num_splats = 0;
    /// The splats are the nodes of a level-of-detail hierarchy (GaussianSplatLodPacking.h):
    /// the cut (GaussianLodCut) writes the view's list of nodes into GeometryStageViewBuffers,
    /// and the stage runs over shader::LodListSlots list slots, not N.
    bool lod = false;
    BufferRange lod_nodes;     ///< shader::GaussianLodNode [N]
    BufferRange lod_children;  ///< uint32 [N - 1]: the inner nodes' children
    BufferRange lod_previous;  ///< uint32 [1]: the cut's walk's last threshold
    uint32_t lod_leaves = 0, lod_inner = 0;
    uint32_t lod_inner_levels = 0;  ///< PackedLodNodes::inner_levels
    int packed_sh_degree = 0;
    uint32_t sh_words_per_splat = 0;
    SplatPrecision precision = SplatPrecision::kExact;
};

/// Per-view buffers, sized from GeometryStageStorageRequirements (offsets aligned to
/// minStorageBufferOffsetAlignment).
struct GeometryStageViewBuffers {
    BufferRange view_params;
    BufferRange projected;
    BufferRange counters;
    BufferRange depth_keys;
    BufferRange splat_indices;  ///< after Record: visible splats in depth order
    BufferRange scan;           ///< after Record: first visible_count words = entry offsets
    BufferRange entry_keys;     ///< after Record: tile index per entry, ascending
    BufferRange entry_values;   ///< after Record: splat index per entry, front to back
    /// Shared by both sorts; its sweep_state is the depth sort's.
    RadixSortScratch sort_scratch;
    /// The tile sort's RadixSweepState (both are cleared with the frame's first transfers).
    BufferRange tile_sort_sweep_state;
    BufferRange tile_counts;  ///< scratch: each visible splat's tile count, by splat index
    /// The composite's state buffer (GaussianCompositeStage::StateBytes of the view's size,
    /// from its start): with per-tile bins (view.choices.binned) the stage counts, fills and
    /// leaves each tile's [begin, end) there, and the composite reads it as it is
    /// (CompositeStageInputs::ranges_written). Unused otherwise (may be empty).
    BufferRange tile_ranges;
    /// A hierarchy's cut (GaussianLodCut; unused otherwise): effective size buckets, their
    /// histogram, the cut as bits, their counts per group, and the list of the cut's nodes
    /// the projection reads.
    BufferRange lod_buckets, lod_histogram, lod_visibility, lod_group_counts, lod_list, lod_walk;
};

/// How a geometry stage is built; the defaults are what renderers use.
struct GeometryStageOptions {
    /// The sorts' algorithm (RadixSort::Algorithm::kDefault: the device's); the chained emit
    /// runs where it is the one sweep (UsesChainedEmit).
    RadixSort::Algorithm sort = RadixSort::Algorithm::kDefault;
    /// Tests: the chained emit's odd blocks publish only their own totals, so look-backs
    /// walk across blocks even where workgroups run one after another (lavapipe).
    bool chained_odd_blocks_aggregate_only = false;
};

class GaussianGeometryStage {
public:
    /// Creates the pipelines that do not depend on the scene (the projection pipelines,
    /// specialised on SH degree / antialias / precision, are made on first use).
    explicit GaussianGeometryStage(const VulkanContext& context, GeometryStageOptions options = {});

    /// Sizes for up to `num_splats` splats and `entry_capacity` tile entries. Throws
    /// core::Open3DError when a count exceeds what the sorts support.
    static GeometryStageStorageRequirements GetStorageRequirements(uint32_t num_splats,
                                                                   uint32_t entry_capacity);

    /// Records geometry stage for one view: writes view.params into buffers.view_params, zeroes the
    /// counters (and, from N, the scan and emit sizes and the depth sort's parameters), for a
    /// hierarchy's nodes (scene.lod) chooses the cut into buffers.lod_list (then N below is
    /// its slot count, view.choices.num_splats), then
    /// project (slot i = splat i, or the list's node i) -> one stable sort of all
    /// N slots by depth (culled splats last, ties by index) -> scan tile counts of the N slots
    /// -> dispatch args (entries that fit; the tile sort's parameters, so no sort runs its setup
    /// pass) -> emit entries -> stable sort by tile (view.choices.tile_bits bits). Every size after
    /// the projection comes from GPU-side counts. `view` must come from PackGaussianView for
    /// this scene and a capacity <= the one the buffers were sized for. Pipelines and passes
    /// are picked from view.choices, the host's own values, not read back from view.params.
    ///
    /// With per-tile bins (view.choices.binned, the default exact order): project (also
    /// counting each tile's entries in buffers.tile_ranges) -> bin scan (each tile's begin,
    /// the entries that fit) -> emit (depth key, slot) into the bins -> sort each tile by
    /// (depth key, slot); the keys end as tile indices, the ranges stay in tile_ranges.
    ///
    /// With the packed key (view.choices.packed_key): no sort of the visible list (scan
    /// and emit follow the append order, sized by a dispatch-args pass), entries keyed by
    /// shader::PackedSortKey, one stable 32-bit sort, then the keys are shifted back to tile
    /// indices. The outputs have the same layout in both modes.
    ///
    /// Synchronisation: the caller orders earlier uses of these buffers before Record (and
    /// makes scene uploads visible to compute reads); afterwards all results are
    /// COMPUTE_SHADER storage writes (the counters also) for the caller to barrier.
    /// With `timestamps` (reset by the caller in this command buffer), the projection and
    /// its dispatch arguments are timed as TimedPass::kProject and everything after as kSort.
    ///
    /// With `params_source` (sizeof(shader::GaussianViewParams) bytes, e.g. a host-mapped
    /// buffer written before each submission) view.params is copied from it when the
    /// command buffer runs instead of being baked into it: one recording then serves every
    /// camera of the same resolution, scene and config.
    void Record(VkCommandBuffer cmd, const GeometryStageSceneBuffers& scene,
                const GeometryStageViewBuffers& buffers, const PackedView& view,
                const GpuTimestamps* timestamps = nullptr,
                const BufferRange* params_source = nullptr);

    /// Whether Record leaves each tile's [begin, end) in buffers.tile_ranges (the composite's
    /// state, which must then be the view's size: CompositeStageInputs::ranges_written): the
    /// per-tile bins and the chained frame (the tile sort's run bounds) do. A range whose
    /// begin exceeds its end is empty.
    bool WritesTileRanges(const GeometryStageChoices& choices) const;
    /// Whether the scan, the capacity cut and the emit run as one chained dispatch
    /// (gaussian_emit_chained.comp): in the exact order (neither the packed key nor the
    /// bins), where the sorts run the one sweep (the look-back needs the device's forward
    /// progress), for a capacity below the look-back words' value range, unless
    /// OPEN3D_CHAINED_EMIT=0 asks for the separate passes (to measure them).
    bool UsesChainedEmit(const GeometryStageChoices& choices) const;

private:
    /// `cut_list`: slot i projects the node the cut's list holds (shader::kSpecCutList).
    VkPipeline GetProjectPipeline(uint32_t sh_degree, bool antialias, SplatPrecision precision,
                                  bool indexed_list, bool cut_list, bool bin_tiles,
                                  bool depth_digits);
    /// The per-tile bins' passes after the projection (RenderConfig SortMode::kExact).
    /// Bindings and push constants are the projection's, still bound.
    void RecordBins(VkCommandBuffer cmd, const PackedView& view, const GpuTimestamps* timestamps);
    void PushBindings(VkCommandBuffer cmd, const GeometryStageSceneBuffers& scene,
                      const GeometryStageViewBuffers& buffers) const;

    const VulkanContext& context_;
    RadixSort sort_;
    GaussianLodCut lod_cut_;
    bool chained_emit_allowed_ = true;  // OPEN3D_CHAINED_EMIT is not 0
    UniqueDescriptorSetLayout set_layout_;
    UniquePipelineLayout pipeline_layout_;
    UniquePipeline scan_;
    UniquePipeline scan_gather_;
    UniquePipeline dispatch_args_;
    UniquePipeline emit_;
    UniquePipeline emit_packed_;   // kEmitPackedKeys
    UniquePipeline unpack_keys_;   // kEmitUnpackKeys
    UniquePipeline emit_binned_;   // kEmitBinned
    UniquePipeline emit_chained_;  // gaussian_emit_chained.comp: scan, cut and emit in one
    UniquePipeline bin_scan_;
    UniquePipeline bin_sort_;
    std::map<uint32_t, UniquePipeline> project_;  // key: degree | antialias << 2 | precision << 3 |
                                                  // indexed << 4 | cut << 5 | bins << 6
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
