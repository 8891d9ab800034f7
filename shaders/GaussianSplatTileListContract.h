// The tile lists' part of the GPU contract (GaussianGeometryStage.cpp after the projection,
// shaders/gaussian_dispatch_args.comp, gaussian_scan.comp, gaussian_emit.comp): the GPU-side
// counters, the tile-count scan, the emit pass, the depth-sorted list's values and the
// packed (tile, depth) sort key. A stage of its own because these passes turn projected
// splats into the per-tile entries the composite reads, whichever sort order is chosen.
// GLSL and C++ as GaussianSplatCommon.h says; C++ gets static_asserts on every offset.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_TILE_LIST_CONTRACT_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_TILE_LIST_CONTRACT_H

#include "GaussianSplatProjectionContract.h"
#include "GaussianSplatRadixSortContract.h"

#ifdef __cplusplus
namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {
#endif

// Workgroup size of the emit pass (one invocation per visible splat).
OPEN3D_SHADER_CONST uint kEmitWorkgroupSize = 256u;
// The tile-count scan: a workgroup scans a block of 256 * 4 = 1024 counts.
OPEN3D_SHADER_CONST uint kScanWorkgroupSize = 256u;
OPEN3D_SHADER_CONST uint kScanItemsPerInvocation = 4u;
OPEN3D_SHADER_CONST uint kScanBlockSize = 1024u;
// Levels of the block-sum hierarchy: 1024^4 counts, far beyond any buffer we allocate.
OPEN3D_SHADER_CONST uint kScanMaxLevels = 4u;
// Prefix sums saturate here: the sum of all tile counts can exceed 2^32 (a camera inside
// a large cloud), and min(a + b, S) of values <= S < 2^31 never wraps. Entry capacities
// are kept below S, so a saturated offset always reads as "does not fit".
OPEN3D_SHADER_CONST uint kScanSaturation = 0x7FFFFFFFu;
// Specialisation constant of gaussian_scan.comp: level 0 gathers the tile counts.
OPEN3D_SHADER_CONST uint kSpecScanGather = 0u;
// Specialisation constant of gaussian_emit.comp: what the pass writes into the entry keys.
OPEN3D_SHADER_CONST uint kSpecEmitMode = 0u;
OPEN3D_SHADER_CONST uint kEmitTileKeys = 0u;    // exact order: key = tile index
OPEN3D_SHADER_CONST uint kEmitPackedKeys = 1u;  // packed option: key = PackedSortKey(...)
OPEN3D_SHADER_CONST uint kEmitUnpackKeys = 2u;  // after the packed sort: key >>= depth bits
OPEN3D_SHADER_CONST uint kEmitBinned = 3u;  // per-tile bins: (depth key, slot) at the tile's cursor

// ---- The chained emit (gaussian_emit_chained.comp, the exact order on GPUs) ----
// The scan of the tile counts, the capacity cut and the emit in one dispatch: a workgroup
// per block of kEmitWorkgroupSize list slots finds the entries of the blocks before it by
// decoupled look-back, with the one-sweep sort's status words (kRadixSweepFlagAggregate /
// kRadixSweepFlagInclusive | value, 0 = not published). They live in the scan buffer, which
// this path does not otherwise use: word kEmitChainedTicketWord hands out block indices in
// the order workgroups start (so a look-back only waits for started blocks), block b's
// status word is kEmitChainedStatusBase + b. The recorder zeroes those words each frame.
OPEN3D_SHADER_CONST uint kEmitChainedTicketWord = 0u;
OPEN3D_SHADER_CONST uint kEmitChainedStatusBase = 1u;
// Specialisation constant of gaussian_emit_chained.comp (tests): 1 makes odd blocks publish
// only their own totals, never their inclusive prefix, so look-backs walk across blocks even
// where workgroups run one after another (GeometryStageOptions).
OPEN3D_SHADER_CONST uint kSpecEmitChainedOddBlocksAggregateOnly = 0u;

// ---- Per-tile bins (SortMode::kExactTileBins) ----
// project (counts per tile) -> gaussian_bin_scan (one workgroup: each tile's begin, the
// entries that fit) -> emit (kEmitBinned: (depth key, slot) at an atomic cursor of each tile)
// -> gaussian_bin_sort (a workgroup per tile sorts its entries by (depth key, slot), which
// is unique, so the order does not depend on the atomics). The bins live in the composite's
// state buffer after its GaussianCompositeState: word kBinRangesWordOffset + 2 t holds tile
// t's begin and the next word its count, then its cursor, then its end.
OPEN3D_SHADER_CONST uint kBinRangesWordOffset = 4u;
OPEN3D_SHADER_CONST uint kBinScanWorkgroupSize = 256u;
OPEN3D_SHADER_CONST uint kBinSortWorkgroupSize = 256u;
// Specialisation constant of gaussian_bin_sort.comp: entries a tile sorts in shared memory
// (a power of two, 8 bytes each); longer tiles sort in place in the entry buffers.
OPEN3D_SHADER_CONST uint kSpecBinSortCapacity = 0u;
OPEN3D_SHADER_CONST uint kBinSortCapacitySmall = 2048u;  // 16 KiB: devices with < 40 KiB
OPEN3D_SHADER_CONST uint kBinSortCapacityLarge = 4096u;  // 32 KiB

// uint indices into GaussianGeometryStageCounters, used as the radix sorter's count_index.
OPEN3D_SHADER_CONST uint kCounterVisibleIndex = 0u;
OPEN3D_SHADER_CONST uint kCounterEntriesIndex = 2u;
OPEN3D_SHADER_CONST uint kCounterNumSplatsIndex = 7u;  // N, written by the recorder

// Indirect dispatch of one scan level: (x, y, z) groups, then the level's element count.
struct GaussianScanLevel {
    uint dispatch_x;
    uint dispatch_y;
    uint dispatch_z;
    uint count;
};

// GPU-side counts of geometry stage (std430). Zeroed by the recorder before the projection;
// read back after the fence for stats and error flags.
struct GaussianGeometryStageCounters {
    uint visible_count;      // splats that passed culling and the visibility mask
    uint requested_entries;  // sum of tile counts (saturates at kScanSaturation)
    uint entry_count;        // tile entries emitted (<= entry_capacity)
    uint error_flags;        // kErrorEntriesDropped | kErrorCountsClamped
    uint emit_dispatch_x;    // VkDispatchIndirectCommand of the emit pass
    uint emit_dispatch_y;
    uint emit_dispatch_z;
    uint num_splats;  // N: the element count of the exact mode's depth sort
    GaussianScanLevel scan_levels[kScanMaxLevels];
    // Scenes with a level-of-detail hierarchy (gaussian_lod_cut.comp): the nodes of the
    // view's cut and the size bucket it opens above (kLodOpenAll: every inner node); with
    // the walk from the root, the inner nodes it visited and how many walks it took (1 or 2).
    uint lod_cut_nodes;
    uint lod_threshold;
    uint lod_walk_visited, lod_walks;
};

// Push constants of gaussian_dispatch_args.comp.
OPEN3D_SHADER_CONST uint kDispatchArgsAfterProject = 0u;  // sizes the scan and emit
OPEN3D_SHADER_CONST uint kDispatchArgsAfterScan = 1u;     // counts the entries that fit
struct GaussianDispatchArgsPushConstants {
    uint mode;        // kDispatchArgsAfterProject / kDispatchArgsAfterScan
    uint num_levels;  // scan levels recorded (1..kScanMaxLevels)
    // After the scan, the tile sort's parameters (RadixSortParamsFor, count = entries that
    // fit) are written here, saving the sort its setup dispatch.
    uint sort_max_count;
    uint sort_target_blocks;
    // The device's maxComputeWorkGroupCount[0]: the emit's, the scan levels' and the tile
    // sort's grids (DispatchGridFor).
    uint max_groups_x;
};

// Push constants of gaussian_scan.comp.
struct GaussianScanPushConstants {
    uint level;        // index into GaussianGeometryStageCounters::scan_levels
    uint base;         // uint offset of this level's data in the scan buffer
    uint sums_base;    // offset of the next level's data, where the block sums go
    uint reserved3;    // was the down-sweep's add flag; kept so the offsets stay put
    uint write_total;  // 1 on the top level: its block sum is the grand total
    uint reserved0;
    uint reserved1;
    uint reserved2;
};

// ---- Sort-key layout of the seed's packed (tile, depth) key, a measured option ----
// key = (tile << depth_bits) | ((floatBitsToUint(norm_depth) << 1) >> tile_bits), with
// tile_bits = bit width of tile_count (the indices and one filler key past them) clamped to
// [kSortKeyMinTileBits, kSortKeyMaxTileBits]
// and depth_bits = kSortKeyBits - tile_bits. The exact default sorts depth (32 bits) and
// then tiles (tile_bits) in two stable sorts (docs/DESIGN.md section 3).
OPEN3D_SHADER_CONST uint kSortKeyBits = 32u;
OPEN3D_SHADER_CONST uint kSortKeyMinTileBits = 1u;
OPEN3D_SHADER_CONST uint kSortKeyMaxTileBits = 31u;

// Normalised depth (z - near) / (far - near) clamped to [0, 1] (NaN -> 0), computed as
// (z - near) * scale with scale = GaussianViewParams::packed_depth_scale. A subtraction and a
// multiplication are correctly rounded in Vulkan and C++ alike, and `precise` forbids the
// driver to fuse or reorder them, so the host reproduces the GPU's keys bit for bit.
OPEN3D_SHADER_FUNC float PackedSortKeyDepth(float z, float near_plane, float scale) {
    OPEN3D_SHADER_PRECISE float d = (z - near_plane) * scale;
    return d > 1.0f ? 1.0f : (d > 0.0f ? d : 0.0f);
}

// (tile << D) | ((floatBitsToUint(norm_depth) << 1) >> T), T = tile_bits in [1, 31],
// D = 32 - T: the sign bit (always 0) is dropped and the top D of the remaining 31 bits
// (8 exponent, D - 8 mantissa) are kept, so keys ascend with (tile, truncated depth).
OPEN3D_SHADER_FUNC uint PackedSortKey(uint tile, float norm_depth, uint tile_bits) {
    uint depth_field = (floatBitsToUint(norm_depth) << 1u) >> tile_bits;
    return (tile << (kSortKeyBits - tile_bits)) | depth_field;
}

// Values of the depth-sorted visible list: the splat index in the low ListIndexBits(N)
// bits and, above them, its entry count (what the projection wrote to tile_counts) in a
// field of ListCountBits(N) bits, or the field's all-ones value when the count does not
// fit below it. The scan then reads the count from the list it walks anyway instead of
// gathering it through the index, a random 4-byte read per splat (61 us of the grid's
// 1080p frame on the H200); only counts at or past the sentinel are gathered.
OPEN3D_SHADER_CONST uint kListCountMaxBits = 8u;
#ifdef __cplusplus
inline int findMSB(uint value) { return int(std::bit_width(value)) - 1; }  // GLSL's, -1 for 0
#endif
OPEN3D_SHADER_FUNC uint ListIndexBits(uint num_splats) {
    return num_splats > 1u ? uint(findMSB(num_splats - 1u)) + 1u : 1u;
}
// At least 5 bits: N <= RadixSort::kMaxCount < 2^27 (asserted in the C++ tests).
OPEN3D_SHADER_FUNC uint ListCountBits(uint num_splats) {
    uint free_bits = 32u - ListIndexBits(num_splats);
    return free_bits < kListCountMaxBits ? free_bits : kListCountMaxBits;
}
OPEN3D_SHADER_FUNC uint ListCountSentinel(uint num_splats) {
    return (1u << ListCountBits(num_splats)) - 1u;
}
OPEN3D_SHADER_FUNC uint PackListValue(uint splat, uint count, uint num_splats) {
    uint sentinel = ListCountSentinel(num_splats);
    uint field = count < sentinel ? count : sentinel;
    return splat | (field << ListIndexBits(num_splats));
}
OPEN3D_SHADER_FUNC uint ListValueSplat(uint value, uint num_splats) {
    return value & ((1u << ListIndexBits(num_splats)) - 1u);
}
// The entry count, or ListCountSentinel(num_splats): read tile_counts[splat].
OPEN3D_SHADER_FUNC uint ListValueCount(uint value, uint num_splats) {
    return value >> ListIndexBits(num_splats);
}

// ---- Scan level sizes ----
// Indirect size of scan level `level` of a scan over `count` elements (level l + 1 scans
// the block sums of level l, ceil(count / kScanBlockSize^l) of them); levels at and past
// `num_levels` are not recorded and get zero groups. gaussian_dispatch_args.comp sizes the
// packed key's scan from visible_count with it, GaussianGeometryStage the exact order's from N.
OPEN3D_SHADER_FUNC GaussianScanLevel ScanLevelFor(uint count, uint level, uint num_levels,
                                                  uint max_groups_x) {
    for (uint l = 0u; l < level; ++l) count = (count + kScanBlockSize - 1u) / kScanBlockSize;
    bool recorded = level < num_levels;
    uvec4 grid = DispatchGridFor((count + kScanBlockSize - 1u) / kScanBlockSize, max_groups_x);
    GaussianScanLevel size;
    size.dispatch_x = recorded ? grid.x : 0u;
    size.dispatch_y = grid.y;
    size.dispatch_z = 1u;
    size.count = recorded ? count : 0u;
    return size;
}

#ifdef __cplusplus
static_assert(kScanBlockSize == kScanWorkgroupSize * kScanItemsPerInvocation);
static_assert(kCounterVisibleIndex * 4 == 0 && kCounterEntriesIndex * 4 == 8);

static_assert(sizeof(GaussianScanLevel) == 16);
static_assert(sizeof(GaussianGeometryStageCounters) == 48 + 16 * kScanMaxLevels);
static_assert(offsetof(GaussianGeometryStageCounters, lod_cut_nodes) == 32 + 16 * kScanMaxLevels);
static_assert(offsetof(GaussianGeometryStageCounters, visible_count) == 4 * kCounterVisibleIndex);
static_assert(offsetof(GaussianGeometryStageCounters, num_splats) == 4 * kCounterNumSplatsIndex);
static_assert(offsetof(GaussianGeometryStageCounters, requested_entries) == 4);
static_assert(offsetof(GaussianGeometryStageCounters, entry_count) == 4 * kCounterEntriesIndex);
static_assert(offsetof(GaussianGeometryStageCounters, error_flags) == 12);
static_assert(offsetof(GaussianGeometryStageCounters, emit_dispatch_x) == 16);
static_assert(offsetof(GaussianGeometryStageCounters, scan_levels) == 32);

static_assert(sizeof(GaussianDispatchArgsPushConstants) == 20);
static_assert(offsetof(GaussianDispatchArgsPushConstants, num_levels) == 4);
static_assert(sizeof(GaussianScanPushConstants) == 32);
static_assert(offsetof(GaussianScanPushConstants, write_total) == 16);
static_assert(offsetof(GaussianGeometryStageCounters, emit_dispatch_y) == 20);
static_assert(offsetof(GaussianGeometryStageCounters, emit_dispatch_z) == 24);
static_assert(offsetof(GaussianScanLevel, count) == 12);
static_assert(offsetof(GaussianDispatchArgsPushConstants, sort_max_count) == 8);
static_assert(offsetof(GaussianDispatchArgsPushConstants, sort_target_blocks) == 12);
static_assert(offsetof(GaussianScanPushConstants, base) == 4);
static_assert(offsetof(GaussianScanPushConstants, sums_base) == 8);

}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_TILE_LIST_CONTRACT_H
