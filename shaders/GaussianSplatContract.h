// The one contract between host code and compute shaders (STYLE.md point 5): binding
// slots, workgroup sizes, push-constant and buffer struct layouts, sort-key constants.
// Compiled as GLSL (#include from shaders/*.comp through GL_GOOGLE_include_directive) and
// as C++ (namespace open3d::visualization::rendering::shader), where every mirrored struct
// gets static_asserts on size and member offsets. Structs use only 4-byte scalars (and, for
// later stages, 16-byte vectors) so std430 and C++ agree without hidden padding.
// This file must never include Vulkan headers: the CPU and Metal layers may read it too.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>

namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {

using uint = uint32_t;
// GLSL vector types as std430 lays them out, for structs of later stages.
struct alignas(16) vec4 {
    float x, y, z, w;
};
struct alignas(16) uvec4 {
    uint32_t x, y, z, w;
};
static_assert(sizeof(vec4) == 16 && sizeof(uvec4) == 16);

#define OPEN3D_SHADER_CONST inline constexpr
#else
#define OPEN3D_SHADER_CONST const
#endif

// ---- Error flags (same bits as RenderStats::error_flags, checked in RadixSort.cpp) ----
OPEN3D_SHADER_CONST uint kErrorEntriesDropped = 1u;
OPEN3D_SHADER_CONST uint kErrorCountsClamped = 2u;

// ---- Radix sort of (uint32 key, uint32 value) pairs: LSD, 8-bit digits ----
OPEN3D_SHADER_CONST uint kRadixSortDigitBits = 8u;
OPEN3D_SHADER_CONST uint kRadixSortBins = 256u;  // 1 << kRadixSortDigitBits
// The key a first pass with drop_max_keys leaves out (RadixSort::DropMaxKeys).
OPEN3D_SHADER_CONST uint kRadixSortDroppedKey = 0xFFFFFFFFu;
// One invocation per bin in the histogram, scan and scatter shaders (asserted below).
OPEN3D_SHADER_CONST uint kRadixSortWorkgroupSize = 256u;
// A workgroup owns a block of 256 * chunks elements, chunks = 1..8 chosen per sort by
// radix_sort_setup.comp from the GPU-side count: the fewest chunks that keep the block count
// at or below kRadixSortTargetBlocks, so a small sort still spreads over the whole GPU
// instead of queueing 16 chunks in a handful of workgroups (the H100 sorted 125k depth keys
// 3x slower with fixed 4096-element blocks). 256 measured best on the H100 (playbot_125k
// 1080p sort 0.232 ms; 128: 0.249, 1024: 0.252, 2048: 0.263). At most 2048 elements, so
// that a block fits the scatter's shared memory for its local reorder (radix_sort_scatter).
OPEN3D_SHADER_CONST uint kRadixSortItemsPerInvocation = 8u;  // chunks per block, at most
OPEN3D_SHADER_CONST uint kRadixSortBlockSize = 2048u;        // elements per block, at most
OPEN3D_SHADER_CONST uint kRadixSortTargetBlocks = 256u;      // GPUs; CPU devices use fewer
// Upper bound of gl_NumSubgroups on any device (the scatter's per-subgroup counts are then
// [32][128] words, 16 KiB of lavapipe's 32), so RadixSort requires minSubgroupSize >=
// kRadixSortWorkgroupSize / kRadixSortMaxSubgroups = 8.
OPEN3D_SHADER_CONST uint kRadixSortMaxSubgroups = 32u;
// Specialisation constants of the radix-sort shaders, set by RadixSort.cpp per device:
// the bound of gl_NumSubgroups there (kRadixSortWorkgroupSize / minSubgroupSize; 8 on
// NVIDIA, whose scatter counts then take 4 KiB), and the scatter's local reorder capacity
// (kRadixSortBlockSize where its shared arrays fit maxComputeSharedMemorySize, else 1).
OPEN3D_SHADER_CONST uint kSpecRadixSortSubgroups = 0u;
OPEN3D_SHADER_CONST uint kSpecRadixSortLocalCapacity = 1u;

// Descriptor set 0 of every radix-sort pipeline (one push-descriptor layout for all).
OPEN3D_SHADER_CONST uint kRadixSortParamsBinding = 0u;     // RadixSortParams
OPEN3D_SHADER_CONST uint kRadixSortCountBinding = 1u;      // uint[]: the count producer's buffer
OPEN3D_SHADER_CONST uint kRadixSortKeysInBinding = 2u;     // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortValuesInBinding = 3u;   // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortKeysOutBinding = 4u;    // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortValuesOutBinding = 5u;  // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortHistogramBinding = 6u;  // uint[bins + bins * max_blocks]
OPEN3D_SHADER_CONST uint kRadixSortNumBindings = 7u;
// Most passes one sort records: 32-bit keys.
OPEN3D_SHADER_CONST uint kRadixSortMaxPasses = 4u;

// Written on the GPU by radix_sort_setup.comp from the element count; the first three
// members are a VkDispatchIndirectCommand for the per-block passes.
struct RadixSortParams {
    uint dispatch_x;  // number of blocks = ceil(count / block_size)
    uint dispatch_y;  // 1
    uint dispatch_z;  // 1
    uint count;       // min(count from the producer, max_count)
    uint num_blocks;  // == dispatch_x, row stride of the histogram table
    uint flags;       // kErrorCountsClamped when the producer's count exceeded max_count
    uint block_size;  // elements per block: kRadixSortWorkgroupSize * (1..16)
    // Subtracted from every key before its digits are taken; a multiple of kRadixSortBins,
    // so the first pass's digit is the key's own. Non-zero only with a key range.
    uint key_base;
    // With PassCount::kFromKeyRange: the kept keys' smallest and largest key, found by the
    // first pass's histogram (atomics from ~0u and 0), and from the setup after the first
    // pass the passes their span needs (1..recorded) and indirect dispatch sizes (x, y, z)
    // per pass of the histogram and scatter (pass_blocks) and of the row scan (pass_rows),
    // zero groups for the passes past range_passes, and of the copy that brings an odd
    // number of passes back to the caller's buffers (copy_blocks). Without it: range
    // passes 0, every pass's sizes as if it runs, copy_blocks zero groups.
    uint key_min;
    uint key_max;
    uint range_passes;
    uint reserved0;
    uvec4 pass_blocks[kRadixSortMaxPasses];
    uvec4 pass_rows[kRadixSortMaxPasses];
    uvec4 copy_blocks;
};

// Push constants of every radix-sort pipeline.
struct RadixSortPushConstants {
    uint shift;          // first key bit of this pass's digit
    uint digit_bits;     // 1..8: bits of this pass's digit (the last pass may be narrower)
    uint count_index;    // uint index of the count within the count binding
    uint max_count;      // capacity of the key/value buffers
    uint target_blocks;  // 1..kRadixSortTargetBlocks: block count the setup aims at
    uint drop_max_keys;  // 1: this pass leaves out pairs with key kRadixSortDroppedKey
    // 1: PassCount::kFromKeyRange (the first pass's histogram finds the kept keys' range,
    // the setup after it decides the passes)
    uint key_range;
    uint num_passes;  // passes recorded: ceil(num_bits / 8)
    // 1: RadixSort::Output::kValuesOnly (the last pass that runs and the copy write no keys)
    uint values_only;
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

#ifdef __cplusplus
static_assert(kRadixSortBins == (1u << kRadixSortDigitBits));
static_assert(kRadixSortWorkgroupSize == kRadixSortBins, "one invocation per bin");
static_assert(kRadixSortBlockSize == kRadixSortWorkgroupSize * kRadixSortItemsPerInvocation);
static_assert(kRadixSortWorkgroupSize % kRadixSortMaxSubgroups == 0);
static_assert(kErrorEntriesDropped == 1u && kErrorCountsClamped == 2u);

static_assert(sizeof(RadixSortParams) == 192);
static_assert(offsetof(RadixSortParams, dispatch_x) == 0);
static_assert(offsetof(RadixSortParams, dispatch_y) == 4);
static_assert(offsetof(RadixSortParams, dispatch_z) == 8);
static_assert(offsetof(RadixSortParams, count) == 12);
static_assert(offsetof(RadixSortParams, num_blocks) == 16);
static_assert(offsetof(RadixSortParams, flags) == 20);
static_assert(offsetof(RadixSortParams, block_size) == 24);
static_assert(offsetof(RadixSortParams, key_base) == 28);
static_assert(offsetof(RadixSortParams, key_min) == 32);
static_assert(offsetof(RadixSortParams, key_max) == 36);
static_assert(offsetof(RadixSortParams, range_passes) == 40);
static_assert(offsetof(RadixSortParams, pass_blocks) == 48);
static_assert(offsetof(RadixSortParams, pass_rows) == 112);
static_assert(offsetof(RadixSortParams, copy_blocks) == 176);

static_assert(sizeof(RadixSortPushConstants) == 48);
static_assert(offsetof(RadixSortPushConstants, target_blocks) == 16);
static_assert(offsetof(RadixSortPushConstants, shift) == 0);
static_assert(offsetof(RadixSortPushConstants, digit_bits) == 4);
static_assert(offsetof(RadixSortPushConstants, count_index) == 8);
static_assert(offsetof(RadixSortPushConstants, max_count) == 12);

}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus

#undef OPEN3D_SHADER_CONST
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_H

// ---- Projection (geometry stage) ----
// Appended by the projection work (vulkan/GaussianProjection.*, GaussianSplatDataPacking.*):
// view parameters, packed splat attributes, projected splats, geometry stage counters, bindings.
// Kept as its own guarded block so the section above can change independently.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_PROJECTION_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_PROJECTION_H

#ifdef __cplusplus
#include <bit>
#include <cmath>

namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {
#define OPEN3D_SHADER_CONST inline constexpr
#else
#define OPEN3D_SHADER_CONST const
#endif

// Side of the square screen tiles in pixels (== RenderConfig.h kTileSize, asserted there).
OPEN3D_SHADER_CONST uint kGaussianTileSize = 16u;
// Upper bound of a projected splat's 3-sigma radius (pixels). ceil(3 sqrt(lambda)) passes
// 2^32 (and 2^31, the CPU's int) for a 1e4-scale splat next to a telephoto camera; the
// float-to-int conversion would be undefined. Clamped, a splat centred within ~1e9 px of
// the image still covers the whole grid (at most 65535 tiles, ~1e6 px, per axis) as its
// true radius would; farther out a float32 centre is not resolved to a tile anyway.
OPEN3D_SHADER_CONST uint kMaxSplatRadius = 1073741824u;  // 2^30, exact in float32
// Workgroup sizes of the geometry stage passes (one invocation per splat / per visible splat).
OPEN3D_SHADER_CONST uint kProjectWorkgroupSize = 256u;
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

// The depth that orders splats and culls at the near plane (RenderConfig::depth_order,
// GaussianSplatSortDepth.h): the original rasterizer's float32 view z, or the camera-relative one.
OPEN3D_SHADER_CONST uint kDepthOrderReference = 0u;
OPEN3D_SHADER_CONST uint kDepthOrderCameraRelative = 1u;

// Precision of the packed attributes (specialisation constant kSpecPrecision).
OPEN3D_SHADER_CONST uint kPrecisionExact = 0u;    // fp32 everything
OPEN3D_SHADER_CONST uint kPrecisionCompact = 1u;  // fp16 scale, rotation, f_dc, SH
// uint words per splat in the shape buffer: scale xyz, rotation wxyz, f_dc rgb.
OPEN3D_SHADER_CONST uint kShapeWordsExact = 10u;   // 10 floats
OPEN3D_SHADER_CONST uint kShapeWordsCompact = 5u;  // 10 halves

// Specialisation constant ids of gaussian_project.comp.
OPEN3D_SHADER_CONST uint kSpecShDegree = 0u;   // 0..3; 0 reads no SH buffer
OPEN3D_SHADER_CONST uint kSpecAntialias = 1u;  // 0 / 1
OPEN3D_SHADER_CONST uint kSpecPrecision = 2u;  // kPrecisionExact / kPrecisionCompact
// 1 (exact order): slot i of the visible list holds splat i (key ~0u when not visible), so
// one stable depth sort of all N slots orders ties by splat index; 0 (packed key): visible
// splats are appended in subgroup order.
OPEN3D_SHADER_CONST uint kSpecIndexedList = 3u;
// Specialisation constant of gaussian_scan.comp: level 0 gathers the tile counts.
OPEN3D_SHADER_CONST uint kSpecScanGather = 0u;
// Specialisation constant of gaussian_emit.comp: what the pass writes into the entry keys.
OPEN3D_SHADER_CONST uint kSpecEmitMode = 0u;
OPEN3D_SHADER_CONST uint kEmitTileKeys = 0u;    // exact order: key = tile index
OPEN3D_SHADER_CONST uint kEmitPackedKeys = 1u;  // packed option: key = PackedSortKey(...)
OPEN3D_SHADER_CONST uint kEmitUnpackKeys = 2u;  // after the packed sort: key >>= depth bits

// Descriptor set 0 of every geometry stage projection pipeline (one push-descriptor layout; each
// shader declares only the bindings it uses).
OPEN3D_SHADER_CONST uint kGeometryStageViewBinding = 0u;       // GaussianViewParams
OPEN3D_SHADER_CONST uint kGeometryStagePositionsBinding = 1u;  // vec4[N]: xyz, sigmoid(opacity)
OPEN3D_SHADER_CONST uint kGeometryStageShapeBinding = 2u;      // uint[N * shape words]
OPEN3D_SHADER_CONST uint kGeometryStageShBinding = 3u;  // uint[N * sh words]; unread at degree 0
OPEN3D_SHADER_CONST uint kGeometryStageVisibilityBinding =
    4u;  // uint[ceil(N / 32)], bit i = splat i
OPEN3D_SHADER_CONST uint kGeometryStageProjectedBinding = 5u;     // GaussianProjectedSplat[N]
OPEN3D_SHADER_CONST uint kGeometryStageCountersBinding = 6u;      // GaussianGeometryStageCounters
OPEN3D_SHADER_CONST uint kGeometryStageDepthKeysBinding = 7u;     // uint[N]: visible depth keys
OPEN3D_SHADER_CONST uint kGeometryStageSplatIndexBinding = 8u;    // uint[N]: visible splat indices
OPEN3D_SHADER_CONST uint kGeometryStageScanBinding = 9u;          // uint[scan words]: all levels
OPEN3D_SHADER_CONST uint kGeometryStageEntryKeysBinding = 10u;    // uint[capacity]: tile index
OPEN3D_SHADER_CONST uint kGeometryStageEntryValuesBinding = 11u;  // uint[capacity]: splat index
OPEN3D_SHADER_CONST uint kGeometryStageSortParamsBinding = 12u;  // RadixSortParams of the next sort
OPEN3D_SHADER_CONST uint kGeometryStageTileCountsBinding = 13u;  // uint[N]: tiles of splat i
OPEN3D_SHADER_CONST uint kGeometryStageNumBindings = 14u;

// uint indices into GaussianGeometryStageCounters, used as the radix sorter's count_index.
OPEN3D_SHADER_CONST uint kCounterVisibleIndex = 0u;
OPEN3D_SHADER_CONST uint kCounterEntriesIndex = 2u;
OPEN3D_SHADER_CONST uint kCounterNumSplatsIndex = 7u;  // N, written by the recorder

// Per-frame view parameters (a readonly storage buffer; only 16-byte members, so std430,
// std140 and C++ agree).
struct GaussianViewParams {
    // Camera-relative projection: p_cam = R ((p - c_hi) - c_lo) (CameraRelative), exact to
    // float32 rounding of p - c even 1e5 from the origin, where R p + t loses ~1e-2.
    vec4 world_to_camera_row0;  // xyz: row 0 of R (world to camera); w: c_lo.x
    vec4 world_to_camera_row1;  // xyz: row 1 of R; w: c_lo.y
    vec4 world_to_camera_row2;  // xyz: row 2 of R; w: c_lo.z
    vec4 camera_center;         // xyz: c_hi, the camera centre rounded to float32; w: 0.
                                // c_lo = float(c - c_hi), the rounding error (double on the host)
    vec4 intrinsics;            // fx, fy, cx, cy (pixels)
    vec4 clip;                  // guard band 1.3 tan(fov_x / 2), 1.3 tan(fov_y / 2), near plane,
                                // packed-key depth scale 1 / (far - near); 0 = exact depth order
    uvec4 image;                // width, height, tiles_x, tiles_y
    uvec4 limits;               // entry capacity used (<= allocated), max_tiles_per_splat,
                                // max_tile_entries_total (clamped below 2^31), tile_bits
    uvec4 scene;                // num_splats, sh_degree evaluated, antialias, sh_words_per_splat
    uvec4 flags;                // scene depth present, precision, shape_words_per_splat,
                                // entry capacity allocated
    vec4 reference_depth_row;   // m2, m6, m10, m14: row 2 of the float32 world-to-view matrix
                                // [R | t], the original rasterizer's (ReferenceViewDepth)
    uvec4 depth_order;          // x: kDepthOrderReference / kDepthOrderCameraRelative; yzw: 0
};

// One projected splat, written for visible splats only, indexed by splat index (std430).
struct GaussianProjectedSplat {
    vec4 center_depth_opacity;  // x, y (pixels), view-space z, opacity (antialias applied)
    vec4 conic;                 // inverse dilated 2D covariance a, b, c; w = the tile-culling
                                // threshold TileCullThreshold
    vec4 color;                 // rgb = max(0, 0.5 + SH), not clamped above; w = det_q,
                                // a c - b^2 of the conic (1 / det of the dilated covariance)
    uvec4 tiles;                // rect min (x | y << 16), rect max (x | y << 16), entries to
                                // emit (the rect's tiles that TileRowSpan keeps), radius
                                // (pixels); rect is [min, max) in tiles
};

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
    uint entry_count;        // tile entries emitted (<= limits.x)
    uint error_flags;        // kErrorEntriesDropped | kErrorCountsClamped
    uint emit_dispatch_x;    // VkDispatchIndirectCommand of the emit pass
    uint emit_dispatch_y;
    uint emit_dispatch_z;
    uint num_splats;  // N: the element count of the exact mode's depth sort
    GaussianScanLevel scan_levels[kScanMaxLevels];
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

// The seed's packed 32-bit sort key (RenderConfig::sort_mode == kPackedKey32), shared by
// gaussian_emit.comp and the C++ tests so both compute the same bits.
#ifdef __cplusplus
#define OPEN3D_SHADER_FUNC inline
#define OPEN3D_SHADER_PRECISE
inline uint floatBitsToUint(float value) { return std::bit_cast<uint>(value); }
inline float uintBitsToFloat(uint value) { return std::bit_cast<float>(value); }
#else
#define OPEN3D_SHADER_FUNC
#define OPEN3D_SHADER_PRECISE precise
#endif

// Normalised depth (z - near) / (far - near) clamped to [0, 1] (NaN -> 0), computed as
// (z - near) * scale with scale = GaussianViewParams::clip.w. A subtraction and a
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

// CameraRelative, SortDepth and ReferenceViewDepth: the depths that order splats.
#include "GaussianSplatSortDepth.h"

// ---- Tile culling: which tiles of the 3DGS rectangle a splat can change ----
// The composite skips a splat at a pixel when alpha = o exp(-q / 2) < 1/255, where
// q = a dx^2 + 2 b dx dy + c dy^2 is the conic's quadratic form at the pixel offset. So only
// tiles that meet the ellipse q <= 2 ln(255 o) get entries; the others could only receive
// skips, and every image stays bit for bit what the full rectangle gives (docs/vulkan.md
// "Tile culling"). Both functions run in float32 with `precise` on the GPU (projection
// count and emission call them on the same stored values) and on the CPU reference.
#ifdef __cplusplus
using std::ceil;
using std::floor;
using std::log;
using std::sqrt;
#endif

// The splat's threshold on q, widened so that rounding cannot cull a tile the composite
// would blend into: +1% (+0.01 absolute), plus 4e-4 (1 + t) a c / det_q for the
// composite's own float32 rounding of q, which is about 8 eps q / (1 - |rho|) <= 1.1e-5 q a c
// / det_q for a conic with correlation rho (1 - |rho| >= det_q / (2 a c)): 40x that bound.
// det_q = a c - b^2 = 1 / det(cov), passed in from the cancellation-free determinant.
// <= 0 (opacity below 1/255, or 0): no pixel reaches the blending threshold.
OPEN3D_SHADER_FUNC float TileCullThreshold(float opacity, float a, float c, float det_q) {
    OPEN3D_SHADER_PRECISE float t = 2.0f * log(255.0f * opacity);
    OPEN3D_SHADER_PRECISE float slack = 1.0f + (t > 0.0f ? t : 0.0f);
    OPEN3D_SHADER_PRECISE float margin = slack * (0.01f + 4e-4f * (a * c / det_q));
    OPEN3D_SHADER_PRECISE float widened = t + margin;
    return widened;
}

// Where the ellipse q <= t reaches within the band of row offsets [lo, hi] (pixel y minus the
// centre's y): x offsets x_l .. x_r (pixel x minus the centre's x) to widen by `margin` on
// either side, as (x_l, x_r, margin, 1); w = 0 when the band misses the ellipse. x_ext,
// y_ext = sqrt(c t / det_q), sqrt(a t / det_q), the ellipse's half extents, finite. For a
// band of rows the right edge x_r(dy) = (-b dy + sqrt(a t - det_q dy^2)) / a is concave in dy
// with its peak at dy* = -b sqrt(t / (det_q c)), so its maximum over the band is at dy*
// clamped to the band (the left edge mirrors it). The reach is widened by 0.5 px + 1/256 of
// the extent for this function's own rounding.
OPEN3D_SHADER_FUNC vec4 EllipseBandReach(float a, float b, float c, float det_q, float t,
                                         float x_ext, float y_ext, float lo, float hi) {
    vec4 band;
    band.x = 0.0f;
    band.y = 0.0f;
    band.z = 0.0f;
    band.w = 0.0f;
    OPEN3D_SHADER_PRECISE float reach = y_ext * (1.0f + 1.0f / 256.0f) + 0.5f;
    lo = lo > -reach ? lo : -reach;
    hi = hi < reach ? hi : reach;
    if (!(lo <= hi)) return band;
    OPEN3D_SHADER_PRECISE float peak = -b * (x_ext / c);
    OPEN3D_SHADER_PRECISE float dy_r = peak < lo ? lo : (peak > hi ? hi : peak);
    OPEN3D_SHADER_PRECISE float dy_l = -peak < lo ? lo : (-peak > hi ? hi : -peak);
    OPEN3D_SHADER_PRECISE float s_r = a * t - det_q * (dy_r * dy_r);
    OPEN3D_SHADER_PRECISE float s_l = a * t - det_q * (dy_l * dy_l);
    OPEN3D_SHADER_PRECISE float x_r = (sqrt(s_r > 0.0f ? s_r : 0.0f) - b * dy_r) / a;
    OPEN3D_SHADER_PRECISE float x_l = (-sqrt(s_l > 0.0f ? s_l : 0.0f) - b * dy_l) / a;
    OPEN3D_SHADER_PRECISE float margin = 0.5f + x_ext * (1.0f / 256.0f);
    band.x = x_l;
    band.y = x_r;
    band.z = margin;
    band.w = 1.0f;
    return band;
}

// Tile columns [first, last) of tile row `ty` that the ellipse q <= t of a splat centred at
// (cx, cy) touches, within the rectangle's columns [rect_x0, rect_x1), packed as
// first | last << 16 (empty: first == last == rect_x0). Pixel (x, y) is evaluated at (x, y), so row
// ty covers pixel rows 16 ty .. 16 ty + 15 and column tx pixel columns 16 tx .. 16 tx + 15
// (EllipseBandReach over the row's band); anything not finite falls back to the whole
// rectangle row.
OPEN3D_SHADER_FUNC uint TileRowSpan(float cx, float cy, float a, float b, float c, float det_q,
                                    float t, uint ty, uint rect_x0, uint rect_x1) {
    uint whole = rect_x0 | (rect_x1 << 16u);
    uint none = rect_x0 | (rect_x0 << 16u);
    if (!(t > 0.0f)) return none;
    OPEN3D_SHADER_PRECISE float y_ext = sqrt(a * t / det_q);
    OPEN3D_SHADER_PRECISE float x_ext = sqrt(c * t / det_q);
    if (!(y_ext < 1e30f && x_ext < 1e30f && a > 0.0f && c > 0.0f)) return whole;
    OPEN3D_SHADER_PRECISE float lo = float(ty * kGaussianTileSize) - cy;
    OPEN3D_SHADER_PRECISE float hi = lo + float(kGaussianTileSize - 1u);
    vec4 band = EllipseBandReach(a, b, c, det_q, t, x_ext, y_ext, lo, hi);
    if (band.w == 0.0f) return none;
    OPEN3D_SHADER_PRECISE float first = ceil((cx + band.x - band.z - 15.0f) / 16.0f);
    OPEN3D_SHADER_PRECISE float last = floor((cx + band.y + band.z) / 16.0f) + 1.0f;
    if (!(first <= last || first > last)) return whole;  // NaN
    first = first > float(rect_x0) ? first : float(rect_x0);
    first = first < float(rect_x1) ? first : float(rect_x1);
    last = last > first ? last : first;
    last = last < float(rect_x1) ? last : float(rect_x1);
    return uint(first) | (uint(last) << 16u);
}

// Tiles of a span from TileRowSpan.
OPEN3D_SHADER_FUNC uint TileSpanCount(uint span) { return (span >> 16u) - (span & 0xFFFFu); }

// ---- Scan level sizes ----
// Indirect size of scan level `level` of a scan over `count` elements (level l + 1 scans
// the block sums of level l, ceil(count / kScanBlockSize^l) of them); levels at and past
// `num_levels` are not recorded and get zero groups. gaussian_dispatch_args.comp sizes the
// packed key's scan from visible_count with it, GaussianGeometryStage the exact order's from N.
OPEN3D_SHADER_FUNC GaussianScanLevel ScanLevelFor(uint count, uint level, uint num_levels) {
    for (uint l = 0u; l < level; ++l) count = (count + kScanBlockSize - 1u) / kScanBlockSize;
    bool recorded = level < num_levels;
    GaussianScanLevel size;
    size.dispatch_x = recorded ? (count + kScanBlockSize - 1u) / kScanBlockSize : 0u;
    size.dispatch_y = 1u;
    size.dispatch_z = 1u;
    size.count = recorded ? count : 0u;
    return size;
}

// ---- Radix sort parameters for an element count ----
// Clamps the count to max_count (kErrorCountsClamped) and chooses the block size: the
// fewest chunks of kRadixSortWorkgroupSize that keep the block count at or below
// target_blocks (clamped to 1..kRadixSortTargetBlocks), 1..kRadixSortItemsPerInvocation
// chunks. radix_sort_setup.comp calls it, and so does a producer that writes the sort's
// parameters itself (gaussian_dispatch_args.comp, and GaussianGeometryStage on the host for the
// depth sort, whose count is N), saving the sort its setup dispatch. No
// overflow: the host keeps max_count far below 2^32 - kRadixSortBlockSize.
OPEN3D_SHADER_FUNC RadixSortParams RadixSortParamsFor(uint count, uint max_count,
                                                      uint target_blocks) {
    RadixSortParams p;
    p.flags = 0u;
    if (count > max_count) {
        count = max_count;
        p.flags = kErrorCountsClamped;
    }
    uint target = target_blocks < 1u ? 1u : target_blocks;
    target = target < kRadixSortTargetBlocks ? target : kRadixSortTargetBlocks;
    uint wave = kRadixSortWorkgroupSize * target;
    uint chunks = (count + wave - 1u) / wave;
    chunks = chunks < 1u ? 1u : chunks;
    chunks = chunks < kRadixSortItemsPerInvocation ? chunks : kRadixSortItemsPerInvocation;
    p.block_size = kRadixSortWorkgroupSize * chunks;
    p.num_blocks = (count + p.block_size - 1u) / p.block_size;
    p.dispatch_x = p.num_blocks;
    p.dispatch_y = 1u;
    p.dispatch_z = 1u;
    p.count = count;
    p.key_base = 0u;
    p.key_min = 0xFFFFFFFFu;
    p.key_max = 0u;
    p.range_passes = 0u;
    p.reserved0 = 0u;
    for (uint pass = 0u; pass < kRadixSortMaxPasses; ++pass) {
        p.pass_blocks[pass] = uvec4(p.num_blocks, 1u, 1u, 0u);
        p.pass_rows[pass] = uvec4(kRadixSortBins, 1u, 1u, 0u);
    }
    p.copy_blocks = uvec4(0u, 1u, 1u, 0u);
    return p;
}
#undef OPEN3D_SHADER_FUNC
#undef OPEN3D_SHADER_PRECISE

#ifdef __cplusplus
static_assert(kScanBlockSize == kScanWorkgroupSize * kScanItemsPerInvocation);
static_assert(kCounterVisibleIndex * 4 == 0 && kCounterEntriesIndex * 4 == 8);

static_assert(sizeof(GaussianViewParams) == 192);
static_assert(offsetof(GaussianViewParams, world_to_camera_row0) == 0);
static_assert(offsetof(GaussianViewParams, world_to_camera_row1) == 16);
static_assert(offsetof(GaussianViewParams, world_to_camera_row2) == 32);
static_assert(offsetof(GaussianViewParams, camera_center) == 48);
static_assert(offsetof(GaussianViewParams, intrinsics) == 64);
static_assert(offsetof(GaussianViewParams, clip) == 80);
static_assert(offsetof(GaussianViewParams, image) == 96);
static_assert(offsetof(GaussianViewParams, limits) == 112);
static_assert(offsetof(GaussianViewParams, scene) == 128);
static_assert(offsetof(GaussianViewParams, flags) == 144);
static_assert(offsetof(GaussianViewParams, reference_depth_row) == 160);
static_assert(offsetof(GaussianViewParams, depth_order) == 176);

static_assert(sizeof(GaussianProjectedSplat) == 64);
static_assert(offsetof(GaussianProjectedSplat, center_depth_opacity) == 0);
static_assert(offsetof(GaussianProjectedSplat, conic) == 16);
static_assert(offsetof(GaussianProjectedSplat, color) == 32);
static_assert(offsetof(GaussianProjectedSplat, tiles) == 48);

static_assert(sizeof(GaussianScanLevel) == 16);
static_assert(sizeof(GaussianGeometryStageCounters) == 32 + 16 * kScanMaxLevels);
static_assert(offsetof(GaussianGeometryStageCounters, visible_count) == 4 * kCounterVisibleIndex);
static_assert(offsetof(GaussianGeometryStageCounters, num_splats) == 4 * kCounterNumSplatsIndex);
static_assert(offsetof(GaussianGeometryStageCounters, requested_entries) == 4);
static_assert(offsetof(GaussianGeometryStageCounters, entry_count) == 4 * kCounterEntriesIndex);
static_assert(offsetof(GaussianGeometryStageCounters, error_flags) == 12);
static_assert(offsetof(GaussianGeometryStageCounters, emit_dispatch_x) == 16);
static_assert(offsetof(GaussianGeometryStageCounters, scan_levels) == 32);

static_assert(sizeof(GaussianDispatchArgsPushConstants) == 16);
static_assert(offsetof(GaussianDispatchArgsPushConstants, num_levels) == 4);
static_assert(sizeof(GaussianScanPushConstants) == 32);
static_assert(offsetof(GaussianScanPushConstants, write_total) == 16);

}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus

#undef OPEN3D_SHADER_CONST
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_PROJECTION_H

// ---- Composite (composite stage) ----
// Appended by the composite work (vulkan/GaussianCompositeStage.*,
// shaders/gaussian_composite*.comp, shaders/gaussian_depth_merge.comp): bindings, push constants,
// the work-stealing state and the blending thresholds. Kept as its own guarded block like the
// geometry stage section.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_COMPOSITE_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_COMPOSITE_H

#ifdef __cplusplus
namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {
#define OPEN3D_SHADER_CONST inline constexpr
#else
#define OPEN3D_SHADER_CONST const
#endif

// One composite workgroup per 16x16 tile, one invocation per pixel; the tile's splats are
// loaded into shared memory in batches of one splat per invocation (48 B each: 12 KiB).
OPEN3D_SHADER_CONST uint kCompositeTileSize = 16u;  // == kGaussianTileSize (asserted in C++)
OPEN3D_SHADER_CONST uint kCompositeWorkgroupSize = 256u;
OPEN3D_SHADER_CONST uint kCompositeBatchSize = 256u;
// Each 32 invocations blend an 8x4 pixel block of the tile (gaussian_composite.glsl).
OPEN3D_SHADER_CONST uint kCompositeBlockWidth = 8u;
OPEN3D_SHADER_CONST uint kCompositeBlockHeight = 4u;
// Pixel blocks of a tile, numbered row-major: block k covers columns
// (k % kCompositeBlocksX) * kCompositeBlockWidth.. and rows (k / kCompositeBlocksX) *
// kCompositeBlockHeight.. of the tile (one bit each in CompositeBlockMask).
OPEN3D_SHADER_CONST uint kCompositeBlocksX = kCompositeTileSize / kCompositeBlockWidth;
OPEN3D_SHADER_CONST uint kCompositeBlocksY = kCompositeTileSize / kCompositeBlockHeight;
OPEN3D_SHADER_CONST uint kCompositeBlocks = kCompositeBlocksX * kCompositeBlocksY;
// Bound of gl_NumSubgroups in a composite workgroup: subgroups of at least 8 invocations,
// which RadixSort already requires of the device.
OPEN3D_SHADER_CONST uint kCompositeMaxSubgroups = kCompositeWorkgroupSize / 8u;
// The depth merge runs 16x16 pixels per workgroup.
OPEN3D_SHADER_CONST uint kDepthMergeWorkgroupSize = 16u;

// The 3DGS blending thresholds as float32 (docs/DESIGN.md section 3; == cpu::kMaxAlpha etc.).
OPEN3D_SHADER_CONST float kCompositeMaxAlpha = 0.99f;
OPEN3D_SHADER_CONST float kCompositeMinAlpha = 1.0f / 255.0f;
OPEN3D_SHADER_CONST float kCompositeMinTransmittance = 0.0001f;

// Specialisation constant of gaussian_composite*.comp and gaussian_depth_merge.comp:
// 1 = a scene depth texture is bound and tested; 0 = it is never read.
OPEN3D_SHADER_CONST uint kSpecSceneDepth = 0u;
// Specialisation constant of gaussian_composite*.comp: which depth images it writes, a sum
// of the bits below (0 = colour only). Each bit drops per-blend arithmetic when clear.
OPEN3D_SHADER_CONST uint kSpecCompositeDepth = 1u;
OPEN3D_SHADER_CONST uint kCompositeExpectedDepthBit = 1u;  // expected depth and alpha images
OPEN3D_SHADER_CONST uint kCompositeMedianDepthBit = 2u;    // median depth image

// Which pixel blocks of a tile a splat can change: bit k is set unless no pixel of block k
// lies in the splat's culling ellipse q <= t (TileCullThreshold, stored in conic.w), found
// per row of blocks with EllipseBandReach as TileRowSpan finds tiles, so a block with a clear
// bit receives only skips, exactly as a culled tile. (x0, y0) is the tile's first pixel,
// (cx, cy) the splat centre; pixel (x, y) is evaluated at (x, y). Nothing finite to bound by
// (a degenerate conic, NaN): every block.
#ifdef __cplusplus
#define OPEN3D_SHADER_FUNC inline
#define OPEN3D_SHADER_PRECISE
#else
#define OPEN3D_SHADER_FUNC
#define OPEN3D_SHADER_PRECISE precise
#endif
OPEN3D_SHADER_FUNC uint CompositeBlockMask(float cx, float cy, float a, float b, float c,
                                           float det_q, float t, float x0, float y0) {
    uint all = (1u << kCompositeBlocks) - 1u;
    uint row = (1u << kCompositeBlocksX) - 1u;
    if (!(t > 0.0f)) return 0u;
    OPEN3D_SHADER_PRECISE float x_ext = sqrt(c * t / det_q);
    OPEN3D_SHADER_PRECISE float y_ext = sqrt(a * t / det_q);
    if (!(x_ext < 1e30f && y_ext < 1e30f && a > 0.0f && c > 0.0f)) return all;
    uint mask = 0u;
    for (uint by = 0u; by < kCompositeBlocksY; ++by) {
        OPEN3D_SHADER_PRECISE float lo = y0 + float(by * kCompositeBlockHeight) - cy;
        OPEN3D_SHADER_PRECISE float hi = lo + float(kCompositeBlockHeight - 1u);
        vec4 band = EllipseBandReach(a, b, c, det_q, t, x_ext, y_ext, lo, hi);
        if (band.w == 0.0f) continue;
        OPEN3D_SHADER_PRECISE float left = cx + band.x - band.z - x0;
        OPEN3D_SHADER_PRECISE float right = cx + band.y + band.z - x0;
        uint columns = 0u;
        for (uint bx = 0u; bx < kCompositeBlocksX; ++bx) {
            float first = float(bx * kCompositeBlockWidth);
            if (right >= first && left <= first + float(kCompositeBlockWidth - 1u)) {
                columns |= 1u << bx;
            }
        }
        if (!(left <= right)) columns = row;  // NaN
        mask |= columns << (by * kCompositeBlocksX);
    }
    return mask;
}
#undef OPEN3D_SHADER_FUNC
#undef OPEN3D_SHADER_PRECISE

// Descriptor set 0 of the composite (push descriptors).
OPEN3D_SHADER_CONST uint kCompositeProjectedBinding = 0u;    // GaussianProjectedSplat[N]
OPEN3D_SHADER_CONST uint kCompositeEntryKeysBinding = 1u;    // uint[capacity]: tile, ascending
OPEN3D_SHADER_CONST uint kCompositeEntryValuesBinding = 2u;  // uint[capacity]: splat index
OPEN3D_SHADER_CONST uint kCompositeCountBinding = 3u;        // uint[]: entry count at count_index
OPEN3D_SHADER_CONST uint kCompositeStateBinding = 4u;        // GaussianCompositeState
OPEN3D_SHADER_CONST uint kCompositeColorBinding = 5u;        // image2D rgba32f / rgba16f
OPEN3D_SHADER_CONST uint kCompositeDepthBinding = 6u;        // image2D r32f: expected view z
OPEN3D_SHADER_CONST uint kCompositeAlphaBinding = 7u;        // image2D r32f: 1 - T
OPEN3D_SHADER_CONST uint kCompositeMedianDepthBinding = 8u;  // image2D r32f: median view z
OPEN3D_SHADER_CONST uint kCompositeSceneDepthBinding = 9u;   // texture2D, reversed-Z
OPEN3D_SHADER_CONST uint kCompositeNumBindings = 10u;

// Descriptor set 0 of the depth merge (push descriptors).
OPEN3D_SHADER_CONST uint kDepthMergeSplatDepthBinding = 0u;  // image2D r32f: splat view z
OPEN3D_SHADER_CONST uint kDepthMergeSplatAlphaBinding = 1u;  // image2D r32f: splat 1 - T
OPEN3D_SHADER_CONST uint kDepthMergeSceneDepthBinding = 2u;  // texture2D, reversed-Z
OPEN3D_SHADER_CONST uint kDepthMergeNormalizedBinding = 3u;  // uimage2D r16ui
OPEN3D_SHADER_CONST uint kDepthMergeLinearBinding = 4u;      // image2D r32f: merged view z
OPEN3D_SHADER_CONST uint kDepthMergeNumBindings = 5u;

// Work-stealing state of one composite dispatch (std430): zeroed by the recorder
// (vkCmdFillBuffer) before every dispatch; each workgroup claims tiles with atomicAdd.
struct GaussianCompositeState {
    uint next_tile;
    uint reserved0;
    uint reserved1;
    uint reserved2;
};

// Push constants of the composite.
struct GaussianCompositePushConstants {
    uvec4 image;       // width, height, tiles_x, tiles_y
    uvec4 entries;     // count_index (uint index in the count binding), capacity,
                       // scene depth flip y (1: row 0 is the bottom row, GL), 0
    vec4 background;   // rgb: out.rgb = C + T * background; w = 0
    vec4 scene_depth;  // x: near of the reversed-Z depth (view z = near / d); y, z, w = 0
};

// Push constants of the depth merge.
struct GaussianDepthMergePushConstants {
    uvec4 image;  // width, height, scene depth flip y, 0
    vec4 range;   // near, far of the normalisation, scene near (z = near / d),
                  // min splat alpha for the splat depth to count
};

#ifdef __cplusplus
static_assert(kCompositeTileSize == kGaussianTileSize);
static_assert(kCompositeTileSize % kCompositeBlockWidth == 0u);
static_assert(kCompositeTileSize % kCompositeBlockHeight == 0u);
static_assert(kCompositeWorkgroupSize == kCompositeTileSize * kCompositeTileSize);
static_assert(kCompositeBatchSize == kCompositeWorkgroupSize, "one splat load per invocation");
static_assert(kCompositeBlocks <= 8u, "CompositeBlockMask's bits are counted in 16-bit fields");
static_assert(kCompositeBlocks * kCompositeBlockWidth * kCompositeBlockHeight ==
              kCompositeWorkgroupSize);

static_assert(sizeof(GaussianCompositeState) == 16);
static_assert(offsetof(GaussianCompositeState, next_tile) == 0);

static_assert(sizeof(GaussianCompositePushConstants) == 64);
static_assert(offsetof(GaussianCompositePushConstants, image) == 0);
static_assert(offsetof(GaussianCompositePushConstants, entries) == 16);
static_assert(offsetof(GaussianCompositePushConstants, background) == 32);
static_assert(offsetof(GaussianCompositePushConstants, scene_depth) == 48);

static_assert(sizeof(GaussianDepthMergePushConstants) == 32);
static_assert(offsetof(GaussianDepthMergePushConstants, image) == 0);
static_assert(offsetof(GaussianDepthMergePushConstants, range) == 16);

}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus

#undef OPEN3D_SHADER_CONST
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_CONTRACT_COMPOSITE_H
