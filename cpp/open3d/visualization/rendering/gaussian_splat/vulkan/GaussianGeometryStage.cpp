#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStage.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdlib>
#include <string>
#include <utility>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatLodPacking.h"
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

static_assert(offsetof(GaussianGeometryStageCounters, emit_dispatch_x) % 4 == 0 &&
                  offsetof(GaussianGeometryStageCounters, scan_levels) % 4 == 0,
              "indirect dispatch arguments need 4-byte offsets");
static_assert(offsetof(GaussianScanLevel, dispatch_x) == offsetof(VkDispatchIndirectCommand, x));
static_assert(sizeof(GaussianViewParams) <= 65536, "vkCmdUpdateBuffer limit");

VkDeviceSize Words(uint64_t n) { return VkDeviceSize(std::max<uint64_t>(n, 1)) * 4; }

uint32_t DivCeil(uint64_t a, uint64_t b) { return static_cast<uint32_t>((a + b - 1) / b); }

// Everything a geometry stage dispatch may read next: storage data and indirect arguments.
void ComputeBarrier(VkCommandBuffer cmd) { RecordComputeToComputeAndIndirect(cmd); }
// Before a dispatch whose indirect size was made visible by an earlier barrier (the host's
// frame-start writes, or a ComputeBarrier after the pass that wrote it): storage only.
void StorageBarrier(VkCommandBuffer cmd) { RecordComputeToCompute(cmd); }

// OPEN3D_CHAINED_EMIT: unset or 1 lets the geometry stage chain its scan, cut and emit
// where it can (UsesChainedEmit); 0 keeps the separate passes, to measure them.
bool ChainedEmitAllowed() {
    const char* env = std::getenv("OPEN3D_CHAINED_EMIT");
    if (env == nullptr || *env == '\0') return true;
    const std::string value = env;
    if (value == "1") return true;
    if (value == "0") return false;
    core::ThrowError("OPEN3D_CHAINED_EMIT is '{}': use 1 or 0 (or unset it)", value);
}

}  // namespace

GaussianGeometryStage::GaussianGeometryStage(const VulkanContext& context,
                                             GeometryStageOptions options)
    : context_(context), sort_(context, options.sort), lod_cut_(context) {
    chained_emit_allowed_ = ChainedEmitAllowed();
    set_layout_ = CreateStorageBufferPushLayout(context, kGeometryStageNumBindings);
    // The scan's or the dispatch-args pass's constants, then the device addresses.
    static_assert(sizeof(GaussianScanPushConstants) <= kGeometryAddressesPushOffset &&
                  sizeof(GaussianDispatchArgsPushConstants) <= kGeometryAddressesPushOffset);
    const uint32_t push_bytes = kGeometryAddressesPushOffset + sizeof(GaussianGeometryAddresses);
    pipeline_layout_ = CreatePipelineLayout(context, set_layout_.Get(), push_bytes);
    const VkPipelineLayout layout = pipeline_layout_.Get();

    const uint32_t gather = 1u;
    const VkSpecializationMapEntry gather_entry{kSpecScanGather, 0, sizeof(uint32_t)};
    const VkSpecializationInfo gather_info{1, &gather_entry, sizeof(uint32_t), &gather};
    scan_ = CreateComputePipeline(context, layout, spirv::kGaussianScan, "gaussian_scan");
    scan_gather_ = CreateComputePipeline(context, layout, spirv::kGaussianScan,
                                         "gaussian_scan (gather)", &gather_info);
    dispatch_args_ = CreateComputePipeline(context, layout, spirv::kGaussianDispatchArgs,
                                           "gaussian_dispatch_args");
    emit_ = CreateComputePipeline(context, layout, spirv::kGaussianEmit, "gaussian_emit");
    const VkSpecializationMapEntry emit_entry{kSpecEmitMode, 0, sizeof(uint32_t)};
    const uint32_t packed_mode = kEmitPackedKeys;
    const uint32_t unpack_mode = kEmitUnpackKeys;
    const VkSpecializationInfo packed_info{1, &emit_entry, sizeof(uint32_t), &packed_mode};
    const VkSpecializationInfo unpack_info{1, &emit_entry, sizeof(uint32_t), &unpack_mode};
    emit_packed_ = CreateComputePipeline(context, layout, spirv::kGaussianEmit,
                                         "gaussian_emit (packed keys)", &packed_info);
    unpack_keys_ = CreateComputePipeline(context, layout, spirv::kGaussianEmit,
                                         "gaussian_emit (unpack keys)", &unpack_info);
    const uint32_t binned_mode = kEmitBinned;
    const VkSpecializationInfo binned_info{1, &emit_entry, sizeof(uint32_t), &binned_mode};
    emit_binned_ = CreateComputePipeline(context, layout, spirv::kGaussianEmit,
                                         "gaussian_emit (bins)", &binned_info);
    const uint32_t aggregate_only = options.chained_odd_blocks_aggregate_only ? 1u : 0u;
    const VkSpecializationMapEntry aggregate_entry{kSpecEmitChainedOddBlocksAggregateOnly, 0,
                                                   sizeof(uint32_t)};
    const VkSpecializationInfo aggregate_info{1, &aggregate_entry, sizeof(uint32_t),
                                              &aggregate_only};
    emit_chained_ = CreateComputePipeline(context, layout, spirv::kGaussianEmitChained,
                                          "gaussian_emit_chained", &aggregate_info);
    bin_scan_ =
        CreateComputePipeline(context, layout, spirv::kGaussianBinScan, "gaussian_bin_scan");
    // A tile sorts in shared memory up to 8-byte pairs filling 32 KiB where the device has
    // room for them beside nothing else (NVIDIA: 48 KiB), else 16 KiB (lavapipe: 32 KiB).
    const uint32_t sort_capacity = context.GetDeviceInfo().max_compute_shared_memory >= 40u * 1024u
                                       ? kBinSortCapacityLarge
                                       : kBinSortCapacitySmall;
    const VkSpecializationMapEntry sort_entry{kSpecBinSortCapacity, 0, sizeof(uint32_t)};
    const VkSpecializationInfo sort_info{1, &sort_entry, sizeof(uint32_t), &sort_capacity};
    bin_sort_ = CreateComputePipeline(context, layout, spirv::kGaussianBinSort, "gaussian_bin_sort",
                                      &sort_info);
}

GeometryStageStorageRequirements GaussianGeometryStage::GetStorageRequirements(
    uint32_t num_splats, uint32_t entry_capacity) {
    if (num_splats > RadixSort::kMaxCount || entry_capacity > RadixSort::kMaxCount) {
        core::ThrowError(
            "GaussianGeometryStage: {} splats / {} tile entries exceed the sort limit {}",
            num_splats, entry_capacity, RadixSort::kMaxCount);
    }
    GeometryStageStorageRequirements r;
    r.view_params_bytes = sizeof(GaussianViewParams);
    r.projected_bytes = VkDeviceSize(std::max(num_splats, 1u)) * sizeof(GaussianProjectedSplat);
    r.counters_bytes = sizeof(GaussianGeometryStageCounters);
    r.depth_keys_bytes = Words(num_splats);
    r.splat_indices_bytes = Words(num_splats);
    r.tile_counts_bytes = Words(num_splats);
    // Level l holds the counts (then offsets) of level l - 1's blocks; the top level is a
    // single block. Its data follows the previous level's in one buffer.
    uint64_t count = std::max(num_splats, 1u);
    uint64_t words = 0;
    r.num_scan_levels = 0;
    while (true) {
        r.scan_level_base[r.num_scan_levels++] = static_cast<uint32_t>(words);
        words += count;
        if (count <= kScanBlockSize) break;
        count = DivCeil(count, kScanBlockSize);
    }
    // The chained emit keeps its ticket and one look-back word per block of list slots there.
    words = std::max<uint64_t>(
        words, kEmitChainedStatusBase + DivCeil(std::max(num_splats, 1u), kEmitWorkgroupSize));
    r.scan_bytes = Words(words);
    r.entry_keys_bytes = Words(entry_capacity);
    r.entry_values_bytes = Words(entry_capacity);
    r.sort = RadixSort::GetStorageRequirements(std::max(num_splats, entry_capacity));
    return r;
}

bool GaussianGeometryStage::WritesTileRanges(const GeometryStageChoices& choices) const {
    return choices.binned || UsesChainedEmit(choices);
}

bool GaussianGeometryStage::UsesChainedEmit(const GeometryStageChoices& choices) const {
    return chained_emit_allowed_ && !choices.packed_key && !choices.binned &&
           sort_.GetAlgorithm() == RadixSort::Algorithm::kOneSweep &&
           choices.entry_capacity_allocated < kRadixSweepValueMask;
}

VkPipeline GaussianGeometryStage::GetProjectPipeline(uint32_t sh_degree, bool antialias,
                                                     SplatPrecision precision, bool indexed_list,
                                                     bool cut_list, bool bin_tiles,
                                                     bool depth_digits) {
    const uint32_t precision_value =
        precision == SplatPrecision::kExact ? kPrecisionExact : kPrecisionCompact;
    const uint32_t key = sh_degree | (antialias ? 4u : 0u) | (precision_value << 3) |
                         (indexed_list ? 16u : 0u) | (cut_list ? 32u : 0u) |
                         (bin_tiles ? 64u : 0u) | (depth_digits ? 128u : 0u);
    auto it = project_.find(key);
    if (it != project_.end()) return it->second.Get();
    const std::array<uint32_t, 7> values{
        sh_degree,          antialias ? 1u : 0u, precision_value,       indexed_list ? 1u : 0u,
        cut_list ? 1u : 0u, bin_tiles ? 1u : 0u, depth_digits ? 1u : 0u};
    const std::array<VkSpecializationMapEntry, 7> entries{{{kSpecShDegree, 0, 4},
                                                           {kSpecAntialias, 4, 4},
                                                           {kSpecPrecision, 8, 4},
                                                           {kSpecIndexedList, 12, 4},
                                                           {kSpecCutList, 16, 4},
                                                           {kSpecBinTiles, 20, 4},
                                                           {kSpecDepthDigits, 24, 4}}};
    const VkSpecializationInfo info{7, entries.data(), sizeof(values), values.data()};
    UniquePipeline pipeline = CreateComputePipeline(
        context_, pipeline_layout_.Get(), spirv::kGaussianProject, "gaussian_project", &info);
    return project_.emplace(key, std::move(pipeline)).first->second.Get();
}

void GaussianGeometryStage::PushBindings(VkCommandBuffer cmd,
                                         const GeometryStageSceneBuffers& scene,
                                         const GeometryStageViewBuffers& buffers) const {
    // Without bins the tile ranges binding is never used but must name a buffer.
    const BufferRange* tile_ranges =
        buffers.tile_ranges.buffer != VK_NULL_HANDLE ? &buffers.tile_ranges : &buffers.counters;
    const std::array<const BufferRange*, kGeometryStageNumBindings> ranges{
        &buffers.view_params,
        &scene.visibility,
        &buffers.counters,
        &buffers.depth_keys,
        &buffers.splat_indices,
        &buffers.scan,
        &buffers.entry_keys,
        &buffers.entry_values,
        &buffers.sort_scratch.params,
        &buffers.tile_counts,
        tile_ranges,
        &buffers.tile_sort_sweep_state,
        &buffers.sort_scratch.histogram,
        &buffers.sort_scratch.sweep_state};
    static_assert(
        kGeometryStageViewBinding == 0 && kGeometryStageVisibilityBinding == 1 &&
            kGeometryStageCountersBinding == 2 && kGeometryStageDepthKeysBinding == 3 &&
            kGeometryStageSplatIndexBinding == 4 && kGeometryStageScanBinding == 5 &&
            kGeometryStageEntryKeysBinding == 6 && kGeometryStageEntryValuesBinding == 7 &&
            kGeometryStageSortParamsBinding == 8 && kGeometryStageTileCountsBinding == 9 &&
            kGeometryStageTileRangesBinding == 10 && kGeometryStageTileSortStateBinding == 11 &&
            kGeometryStageSortStatusBinding == 12 && kGeometryStageDepthSortStateBinding == 13,
        "ranges above are listed in binding order");
    std::array<VkDescriptorBufferInfo, kGeometryStageNumBindings> infos{};
    std::array<VkWriteDescriptorSet, kGeometryStageNumBindings> writes{};
    for (uint32_t i = 0; i < kGeometryStageNumBindings; ++i) {
        const BufferRange& range = *ranges[i];
        if (range.buffer == VK_NULL_HANDLE) {
            core::ThrowError("GaussianGeometryStage: binding {} has no buffer", i);
        }
        infos[i] = {range.buffer, range.offset, range.size};
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    context_.GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_.Get(),
                                       0, kGeometryStageNumBindings, writes.data());
    // The buffers a splat count can grow past one binding's range go by device address.
    const auto shape = DeviceAddressWords(scene.shape, "GaussianGeometryStage: the shape words");
    const auto sh = DeviceAddressWords(scene.sh, "GaussianGeometryStage: the SH words");
    const auto projected =
        DeviceAddressWords(buffers.projected, "GaussianGeometryStage: the projected records");
    const auto positions =
        DeviceAddressWords(scene.positions, "GaussianGeometryStage: the positions");
    const GaussianGeometryAddresses addresses{
        shape[0], shape[1], sh[0], sh[1], projected[0], projected[1], positions[0], positions[1]};
    vkCmdPushConstants(cmd, pipeline_layout_.Get(), VK_SHADER_STAGE_COMPUTE_BIT,
                       kGeometryAddressesPushOffset, sizeof(addresses), &addresses);
}

void GaussianGeometryStage::Record(VkCommandBuffer cmd, const GeometryStageSceneBuffers& in_scene,
                                   const GeometryStageViewBuffers& buffers, const PackedView& view,
                                   const GpuTimestamps* timestamps,
                                   const BufferRange* params_source) {
    if (timestamps) timestamps->RecordBegin(cmd, TimedPass::kProject);
    // A hierarchy's nodes are drawn through the view's cut: the projection reads the list of
    // its nodes at the visibility binding, and every pass after the cut runs over the list's
    // slots (LodListSlots of the budget), not the nodes.
    GeometryStageSceneBuffers scene = in_scene;
    if (scene.lod) scene.visibility = buffers.lod_list;
    // (The parameters may come from params_source: the host's choices carry the slot count.)
    const GaussianViewParams& params = view.params;
    const GeometryStageChoices& choices = view.choices;
    const uint32_t n = choices.num_splats;
    const uint32_t capacity = choices.entry_capacity_allocated;
    // Per-splat passes lay their workgroups out in rows past this (DispatchGridFor).
    const uint32_t max_groups_x = sort_.GetMaxGroupsX();
    const bool packed_key = choices.packed_key;
    const bool slots_fit = scene.lod ? n >= 1 && n <= scene.lod_leaves : n == scene.num_splats;
    if (!slots_fit || choices.entry_capacity > capacity) {
        core::ThrowError(
            "GaussianGeometryStage: view parameters for {} splats / capacity {} do not "
            "match the scene ({} splats{})",
            n, choices.entry_capacity, scene.lod ? scene.lod_leaves : scene.num_splats,
            scene.lod ? ", the most a cut of its hierarchy holds" : "");
    }
    const GeometryStageStorageRequirements need = GetStorageRequirements(n, capacity);
    const VkPipelineLayout layout = pipeline_layout_.Get();
    const VkBuffer counters = buffers.counters.buffer;
    const VkDeviceSize counters_offset = buffers.counters.offset;
    const auto counter_range = [&](uint32_t index) {
        return BufferRange{counters, counters_offset + 4 * index, 4};
    };

    // Per-frame inputs, written in the command buffer (no mapped memory, no hidden upload) or
    // copied from the caller's source when the recording is re-submitted with new cameras.
    if (params_source != nullptr) {
        const VkBufferCopy region{params_source->offset, buffers.view_params.offset,
                                  sizeof(params)};
        vkCmdCopyBuffer(cmd, params_source->buffer, buffers.view_params.buffer, 1, &region);
    } else {
        vkCmdUpdateBuffer(cmd, buffers.view_params.buffer, buffers.view_params.offset,
                          sizeof(params), &params);
    }
    // Counters start at zero but for N, the element count of the exact mode's depth sort
    // (the sorter reads counts from GPU memory). In the exact order the scan and the emit
    // run over all N slots of the depth-sorted list (culled splats sort last and count no
    // tiles), so their sizes and the depth sort's parameters are known here: no
    // dispatch-args pass between the projection and the sort.
    GaussianGeometryStageCounters initial_counters{};
    initial_counters.num_splats = n;
    if (!packed_key) {
        const uvec4 emit = DispatchGridFor(DivCeil(n, kEmitWorkgroupSize), max_groups_x);
        initial_counters.emit_dispatch_x = emit.x;
        initial_counters.emit_dispatch_y = emit.y;
        initial_counters.emit_dispatch_z = 1;
        for (uint32_t level = 0; level < kScanMaxLevels; ++level) {
            initial_counters.scan_levels[level] =
                ScanLevelFor(n, level, need.num_scan_levels, max_groups_x);
        }
        const RadixSortParams depth_sort =
            RadixSortParamsFor(n, std::max(n, 1u), sort_.GetTargetBlocks(), max_groups_x);
        vkCmdUpdateBuffer(cmd, buffers.sort_scratch.params.buffer,
                          buffers.sort_scratch.params.offset, sizeof(depth_sort), &depth_sort);
    }
    vkCmdUpdateBuffer(cmd, counters, counters_offset, sizeof(initial_counters), &initial_counters);
    // The chained emit (the exact order where the sorts run the one sweep) scans, cuts and
    // emits in one dispatch; its ticket and look-back words start at zero.
    const bool chained = UsesChainedEmit(choices);
    const uint32_t chained_blocks = DivCeil(std::max(n, 1u), kEmitWorkgroupSize);
    if (chained) {
        vkCmdFillBuffer(cmd, buffers.scan.buffer, buffers.scan.offset,
                        4 * VkDeviceSize(kEmitChainedStatusBase + chained_blocks), 0u);
    }
    // Both sorts' one-sweep states start at zero (the multi-pass sort reads neither).
    RadixSortScratch depth_sort_scratch = buffers.sort_scratch;
    RadixSortScratch tile_sort_scratch = buffers.sort_scratch;
    tile_sort_scratch.sweep_state = buffers.tile_sort_sweep_state;
    if (sort_.GetAlgorithm() == RadixSort::Algorithm::kOneSweep) {
        RadixSort::RecordClearSweepState(cmd, depth_sort_scratch.sweep_state);
        RadixSort::RecordClearSweepState(cmd, tile_sort_scratch.sweep_state);
        depth_sort_scratch.sweep_state_cleared = true;
        // With the chained emit the projection counts the depth sort's digits (kSpecDepthDigits).
        depth_sort_scratch.sweep_histogram_written = chained;
        tile_sort_scratch.sweep_state_cleared = true;
    }
    const VkDeviceSize ranges_bytes =
        4 * (kBinRangesWordOffset + 2 * VkDeviceSize(choices.num_tiles));
    if (WritesTileRanges(choices) &&
        (buffers.tile_ranges.buffer == VK_NULL_HANDLE ||
         (buffers.tile_ranges.size != VK_WHOLE_SIZE && buffers.tile_ranges.size < ranges_bytes))) {
        core::ThrowError(
            "GaussianGeometryStage: the ranges of {} tiles need {} bytes of tile ranges (the "
            "composite's state), {} given",
            choices.num_tiles, ranges_bytes,
            buffers.tile_ranges.buffer == VK_NULL_HANDLE ? 0 : buffers.tile_ranges.size);
    }
    if (choices.binned) {
        // Every tile's count starts at 0 (and the composite's tile counter, which it zeroes
        // again itself). The chained emit sets the ranges up itself.
        vkCmdFillBuffer(cmd, buffers.tile_ranges.buffer, buffers.tile_ranges.offset, ranges_bytes,
                        0u);
    }
    RecordMemoryBarrier(
        cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
        VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
            VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);

    // 0. Level of detail: the view's cut of the hierarchy becomes the projection's list.
    if (scene.lod) {
        LodCutBuffers cut;
        cut.view_params = buffers.view_params;
        cut.positions = scene.positions;
        cut.nodes = scene.lod_nodes;
        cut.children = scene.lod_children;
        cut.buckets = buffers.lod_buckets;
        cut.histogram = buffers.lod_histogram;
        cut.counters = buffers.counters;
        cut.visibility = buffers.lod_visibility;
        cut.group_counts = buffers.lod_group_counts;
        cut.list = buffers.lod_list;
        cut.walk = buffers.lod_walk;
        cut.previous = scene.lod_previous;
        cut.num_leaves = scene.lod_leaves;
        cut.num_inner = scene.lod_inner;
        cut.list_slots = n;
        const bool walk = WalksLodCut(choices.lod_cut_search, scene.lod_inner, scene.lod_leaves, n);
        cut.walk_levels = walk ? scene.lod_inner_levels : 0u;
        if (cut.num_leaves + cut.num_inner != scene.num_splats) {
            core::ThrowError("GaussianGeometryStage: a hierarchy of {} + {} nodes for {} splats",
                             cut.num_leaves, cut.num_inner, scene.num_splats);
        }
        if (timestamps) timestamps->RecordBegin(cmd, TimedPass::kLodCut);
        lod_cut_.Record(cmd, cut, timestamps);
        ComputeBarrier(cmd);
        if (timestamps) timestamps->RecordEnd(cmd, TimedPass::kLodCut);
    }

    // 1. Project: visible splats -> (depth key, splat index) list, visible_count.
    PushBindings(cmd, scene, buffers);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE,
                      GetProjectPipeline(choices.sh_degree, choices.antialias, scene.precision,
                                         !packed_key, scene.lod, choices.binned, chained));
    if (n > 0) {
        const uvec4 grid = DispatchGridFor(DivCeil(n, kProjectWorkgroupSize), max_groups_x);
        RecordDispatch(cmd, grid.x, grid.y, 1);
    }
    // Next: the depth sort (host-written sizes) or the after-project dispatch args (direct).
    StorageBarrier(cmd);

    // 2. Packed key: the scan and the emit follow the append order of the visible splats,
    // sized on the GPU from visible_count.
    GaussianDispatchArgsPushConstants args{};
    args.num_levels = need.num_scan_levels;
    args.sort_target_blocks = sort_.GetTargetBlocks();
    args.max_groups_x = max_groups_x;
    if (packed_key) {
        args.mode = kDispatchArgsAfterProject;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, dispatch_args_.Get());
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(args), &args);
        RecordDispatch(cmd, 1, 1, 1);
        ComputeBarrier(cmd);
    }
    if (timestamps) {
        timestamps->RecordEnd(cmd, TimedPass::kProject);
        timestamps->RecordBegin(cmd, TimedPass::kSort);
    }
    if (choices.binned) {
        RecordBins(cmd, view, timestamps);
        if (timestamps) timestamps->RecordEnd(cmd, TimedPass::kSort);
        return;
    }

    // 3. Exact depth order with ties by splat index: slot i of the list holds splat i (culled
    // and hidden splats carry the key ~0u), so one stable sort of the N slots by the 32-bit
    // depth key puts the visible splats first, front to back, ties in index order. Its first
    // pass drops the ~0u keys and the other three sort the visible_count kept ones
    // (RadixSort::DropMaxKeys; a visible splat's depth is positive, never ~0u); slots past
    // visible_count are stale afterwards, which the scan and the emit never read. Of those
    // three, only the ones the visible depth keys' span needs run (PassCount::kFromKeyRange):
    // two when the farthest visible splat is less than 2-4 times as far as the nearest.
    // The packed key, like the seed, keeps the projection's append order: its one entry
    // sort decides the depth order, and measuring its error means not helping it here.
    const auto begin = [&](TimedPass pass) {
        if (timestamps) timestamps->RecordBegin(cmd, pass);
    };
    const auto end = [&](TimedPass pass) {
        if (timestamps) timestamps->RecordEnd(cmd, pass);
    };
    if (!packed_key) {
        begin(TimedPass::kDepthSort);
        const RadixSort::DropMaxKeys drop_culled{counter_range(kCounterVisibleIndex)};
        sort_.Record(cmd, buffers.depth_keys, buffers.splat_indices, depth_sort_scratch,
                     counter_range(kCounterNumSplatsIndex), std::max(n, 1u), 32,
                     RadixSort::Params::kWrittenByProducer, &drop_culled,
                     RadixSort::PassCount::kFromKeyRange, RadixSort::Output::kValuesOnly);
        StorageBarrier(cmd);  // the scan's sizes are the host's in the exact order
        end(TimedPass::kDepthSort);
    }
    begin(TimedPass::kScanEmit);
    const VkDeviceSize emit_args =
        counters_offset + offsetof(GaussianGeometryStageCounters, emit_dispatch_x);
    args.sort_max_count = std::max(capacity, 1u);
    PushBindings(cmd, scene, buffers);  // the sorts bound their own layout
    if (chained) {
        // 4-6 in one dispatch: a workgroup per block of list slots finds its entries' offset
        // by look-back, cuts at the capacity and emits (gaussian_emit_chained.comp).
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, emit_chained_.Get());
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(args), &args);
        // Spare workgroups beyond the blocks only clear tile ranges and the tile sort's first
        // status rows, so that a frame of few splats does not leave them to one workgroup (at
        // most four words a thread).
        const uint32_t clear_groups =
            DivCeil(std::max(choices.num_tiles, kRadixSortTargetBlocks * kRadixSortBins),
                    4 * kEmitWorkgroupSize);
        const uvec4 grid = DispatchGridFor(std::max(chained_blocks, clear_groups), max_groups_x);
        RecordDispatch(cmd, grid.x, grid.y, 1);
        ComputeBarrier(cmd);
    } else {
        // 4. Exclusive scan of the tile counts in depth order, up the block levels (readers
        // add the levels above a slot themselves: ScanOffset in gaussian_scan_offset.glsl).
        GaussianScanPushConstants scan{};
        for (uint32_t level = 0; level < need.num_scan_levels; ++level) {
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE,
                              level == 0 ? scan_gather_.Get() : scan_.Get());
            scan.level = level;
            scan.base = need.scan_level_base[level];
            scan.sums_base =
                level + 1 < need.num_scan_levels ? need.scan_level_base[level + 1] : 0u;
            scan.write_total = level + 1 == need.num_scan_levels ? 1u : 0u;
            vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(scan), &scan);
            RecordDispatchIndirect(cmd, counters,
                                   counters_offset +
                                       offsetof(GaussianGeometryStageCounters, scan_levels) +
                                       level * sizeof(GaussianScanLevel));
            // The next level's size sits in the counters this level writes to (its total,
            // error flags): the validation layer tracks a bound buffer as one range, so it
            // wants the indirect access in the barrier although the words differ.
            ComputeBarrier(cmd);
        }

        // 5. How many entries fit (whole splats, front to back) -> entry_count, error flags.
        args.mode = kDispatchArgsAfterScan;
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, dispatch_args_.Get());
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(args), &args);
        RecordDispatch(cmd, 1, 1, 1);
        ComputeBarrier(cmd);  // the emit's size is in the counters written here (see above)

        // 6. Emit (tile, splat) entries in list order at the scanned offsets: tile keys in
        // depth order, or packed (tile, truncated depth) keys.
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE,
                          packed_key ? emit_packed_.Get() : emit_.Get());
        RecordDispatchIndirect(cmd, counters, emit_args);
        ComputeBarrier(cmd);
    }
    end(TimedPass::kScanEmit);

    // 7. Stable sort by tile index only: each tile keeps the depth order of step 3. The
    // packed key sorts all 32 bits (4 passes, as the seed), then shifts back to tiles.
    begin(TimedPass::kTileSort);
    tile_sort_scratch.sweep_histogram_written = chained;  // the chained emit counted the digits
    // In the chained frame the sort's last pass leaves each tile's range in the composite's
    // state (the chained emit set them to empty), in place of the composite's ranges pass.
    RadixSort::RunBounds tile_runs;
    tile_runs.ranges = buffers.tile_ranges;
    tile_runs.word_offset = kBinRangesWordOffset;
    tile_runs.num_keys = choices.num_tiles;
    sort_.Record(cmd, buffers.entry_keys, buffers.entry_values, tile_sort_scratch,
                 counter_range(kCounterEntriesIndex), std::max(capacity, 1u),
                 packed_key ? kSortKeyBits : choices.tile_bits,
                 RadixSort::Params::kWrittenByProducer, nullptr, RadixSort::PassCount::kAll,
                 RadixSort::Output::kKeysAndValues, chained ? &tile_runs : nullptr);
    if (packed_key) {
        ComputeBarrier(cmd);
        PushBindings(cmd, scene, buffers);  // the sort bound its own layout
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, unpack_keys_.Get());
        RecordDispatchIndirect(cmd, counters, emit_args);
    }
    end(TimedPass::kTileSort);
    end(TimedPass::kSort);
}

void GaussianGeometryStage::RecordBins(VkCommandBuffer cmd, const PackedView& view,
                                       const GpuTimestamps* timestamps) {
    const uint32_t n = view.choices.num_splats;
    const uint32_t tiles = view.choices.num_tiles;
    const uint32_t max_groups_x = sort_.GetMaxGroupsX();
    const auto begin = [&](TimedPass pass) {
        if (timestamps) timestamps->RecordBegin(cmd, pass);
    };
    const auto end = [&](TimedPass pass) {
        if (timestamps) timestamps->RecordEnd(cmd, pass);
    };
    // The projection counted each tile's entries. One workgroup scans them into begins.
    begin(TimedPass::kScanEmit);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, bin_scan_.Get());
    RecordDispatch(cmd, 1, 1, 1);
    ComputeBarrier(cmd);
    // Every visible slot writes (depth key, slot) into the bins of its tiles.
    if (n > 0) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, emit_binned_.Get());
        const uvec4 grid = DispatchGridFor(DivCeil(n, kEmitWorkgroupSize), max_groups_x);
        RecordDispatch(cmd, grid.x, grid.y, 1);
        ComputeBarrier(cmd);
    }
    end(TimedPass::kScanEmit);
    // A workgroup per tile orders its bin.
    begin(TimedPass::kTileSort);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, bin_sort_.Get());
    const uvec4 grid = DispatchGridFor(std::max(tiles, 1u), max_groups_x);
    RecordDispatch(cmd, grid.x, grid.y, 1);
    end(TimedPass::kTileSort);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
