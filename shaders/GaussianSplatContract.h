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
// One invocation per bin in the histogram, scan and scatter shaders (asserted below).
OPEN3D_SHADER_CONST uint kRadixSortWorkgroupSize = 256u;
// Elements per invocation: a workgroup owns a block of 256 * 16 = 4096 elements.
OPEN3D_SHADER_CONST uint kRadixSortItemsPerInvocation = 16u;
OPEN3D_SHADER_CONST uint kRadixSortBlockSize = 4096u;
// Upper bound of gl_NumSubgroups, sizing the shared arrays of per-subgroup totals, so
// RadixSort requires minSubgroupSize >= kRadixSortWorkgroupSize / kRadixSortMaxSubgroups = 4.
OPEN3D_SHADER_CONST uint kRadixSortMaxSubgroups = 64u;

// Descriptor set 0 of every radix-sort pipeline (one push-descriptor layout for all).
OPEN3D_SHADER_CONST uint kRadixSortParamsBinding = 0u;     // RadixSortParams
OPEN3D_SHADER_CONST uint kRadixSortCountBinding = 1u;      // uint[]: the count producer's buffer
OPEN3D_SHADER_CONST uint kRadixSortKeysInBinding = 2u;     // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortValuesInBinding = 3u;   // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortKeysOutBinding = 4u;    // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortValuesOutBinding = 5u;  // uint[max_count]
OPEN3D_SHADER_CONST uint kRadixSortHistogramBinding = 6u;  // uint[bins + bins * max_blocks]
OPEN3D_SHADER_CONST uint kRadixSortNumBindings = 7u;

// Written on the GPU by radix_sort_setup.comp from the element count; the first three
// members are a VkDispatchIndirectCommand for the per-block passes.
struct RadixSortParams {
    uint dispatch_x;  // number of blocks = ceil(count / kRadixSortBlockSize)
    uint dispatch_y;  // 1
    uint dispatch_z;  // 1
    uint count;       // min(count from the producer, max_count)
    uint num_blocks;  // == dispatch_x, row stride of the histogram table
    uint flags;       // kErrorCountsClamped when the producer's count exceeded max_count
    uint reserved0;
    uint reserved1;
};

// Push constants of every radix-sort pipeline.
struct RadixSortPushConstants {
    uint shift;        // first key bit of this pass's digit
    uint digit_bits;   // 1..8: bits of this pass's digit (the last pass may be narrower)
    uint count_index;  // uint index of the count within the count binding
    uint max_count;    // capacity of the key/value buffers
};

// ---- Sort-key layout of the seed's packed (tile, depth) key, a measured option ----
// key = (tile << depth_bits) | ((floatBitsToUint(norm_depth) << 1) >> tile_bits), with
// tile_bits = ceil(log2(tile_count)) clamped to [kSortKeyMinTileBits, kSortKeyMaxTileBits]
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

static_assert(sizeof(RadixSortParams) == 32);
static_assert(offsetof(RadixSortParams, dispatch_x) == 0);
static_assert(offsetof(RadixSortParams, dispatch_y) == 4);
static_assert(offsetof(RadixSortParams, dispatch_z) == 8);
static_assert(offsetof(RadixSortParams, count) == 12);
static_assert(offsetof(RadixSortParams, num_blocks) == 16);
static_assert(offsetof(RadixSortParams, flags) == 20);
static_assert(offsetof(RadixSortParams, reserved0) == 24);
static_assert(offsetof(RadixSortParams, reserved1) == 28);

static_assert(sizeof(RadixSortPushConstants) == 16);
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
