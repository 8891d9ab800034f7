// The radix sort's part of the GPU contract (RadixSort.cpp, shaders/radix_sort_*.comp):
// digit and block sizes, specialisation constants, the push-descriptor bindings, the
// GPU-written RadixSortParams (also an indirect dispatch command) and the push constants,
// and RadixSortParamsFor, which the setup shader and the sort's producers share. A stage of
// its own because the geometry stage's two sorts and the tests all run it unchanged.
// GLSL and C++ as GaussianSplatCommon.h says; C++ gets static_asserts on every offset.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_RADIX_SORT_CONTRACT_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_RADIX_SORT_CONTRACT_H

#include "GaussianSplatCommon.h"

#ifdef __cplusplus
namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {
#endif

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
// RadixSweepState of a one-sweep sort (the multi-pass sort binds a placeholder there).
OPEN3D_SHADER_CONST uint kRadixSortSweepStateBinding = 7u;
// uint[]: where the one-sweep sort's last pass leaves each key's run of the sorted output
// (RadixSort::RunBounds; a placeholder otherwise): words run_offset + 2 key (begin, lowered
// with atomicMin) and + 1 (end, raised with atomicMax).
OPEN3D_SHADER_CONST uint kRadixSortRunBoundsBinding = 8u;
OPEN3D_SHADER_CONST uint kRadixSortNumBindings = 9u;
// Most passes one sort records: 32-bit keys.
OPEN3D_SHADER_CONST uint kRadixSortMaxPasses = 4u;

// Written on the GPU by radix_sort_setup.comp from the element count; the first three
// members are a VkDispatchIndirectCommand for the per-block passes.
struct RadixSortParams {
    uint dispatch_x;  // the blocks' grid, DispatchGridFor(num_blocks, max_groups_x)
    uint dispatch_y;
    uint dispatch_z;  // 1
    uint count;       // min(count from the producer, max_count)
    uint num_blocks;  // ceil(count / block_size), row stride of the histogram table
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
    // The one-sweep histogram's grid: min(num_blocks, kRadixSweepHistogramGroups)
    // workgroups, each taking every sweep_groups-th block (x, y, z, sweep_groups).
    uvec4 sweep_histogram_grid;
};

// ---- One sweep per digit (RadixSort::Algorithm::kOneSweep, docs/radix-sort.md) ----
// One histogram dispatch counts the digits of every pass at once; then each pass is a
// single scatter dispatch in which a block finds its output offsets by decoupled look-back:
// it publishes its own digit counts (aggregate) in a status word per (block, digit), then
// adds its predecessors' words back to the first one that carries an inclusive prefix.
// A status word: flag in the top two bits, count below (counts stay below 2^30:
// RadixSort keeps a one-sweep sort's max_count under it).
OPEN3D_SHADER_CONST uint kRadixSweepFlagAggregate = 0x40000000u;
OPEN3D_SHADER_CONST uint kRadixSweepFlagInclusive = 0x80000000u;
OPEN3D_SHADER_CONST uint kRadixSweepValueMask = 0x3FFFFFFFu;
// Most workgroups of the one-sweep histogram: each adds its counts to the global
// histogram with one atomic per non-zero bin, so a sort of many blocks takes several
// blocks per workgroup instead of more atomics.
OPEN3D_SHADER_CONST uint kRadixSweepHistogramGroups = 1024u;
// Specialisation constant (tests only): 1 makes every odd block publish its aggregate
// and never its inclusive prefix, so look-backs walk across several blocks even where
// workgroups run one after another (lavapipe with one thread).
OPEN3D_SHADER_CONST uint kSpecRadixSweepOddBlocksAggregateOnly = 2u;
// The one-sweep scatter's shared keys for the run bounds where it does not reorder blocks in
// shared memory (kRadixSortBlockSize in the pipeline that writes run bounds, else 1).
OPEN3D_SHADER_CONST uint kSpecRadixSortRunCapacity = 3u;

// Zeroed before every one-sweep sort (vkCmdFillBuffer; RadixSort::RecordClearSweepState).
struct RadixSweepState {
    // Digit counts of the kept keys, pass-major: [pass][digit].
    uint histogram[kRadixSortMaxPasses * kRadixSortBins];
    // Per pass, the next block index to hand out: blocks take their index in the order
    // they start, so every block a look-back waits for has started (forward progress).
    uint next_block[kRadixSortMaxPasses];
    uint reserved[4];
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
    // The device's maxComputeWorkGroupCount[0]: the per-block passes' grids
    // (DispatchGridFor) that the setup writes.
    uint max_groups_x;
    uint num_bits;  // the sort's key bits (the one-sweep histogram counts every pass)
    // 1: a one-sweep sort (the copy then counts the kept pairs from the sweep state)
    uint sweep;
    // RadixSort::RunBounds: keys below run_keys get their run written by the last pass
    // (0: none), at word run_offset + 2 key of the run-bounds binding.
    uint run_keys;
    uint run_offset;
};

// The bits of pass `pass`'s digit in a sort of `num_bits` key bits: 8, the last pass's fewer.
OPEN3D_SHADER_FUNC uint RadixSortDigitBits(uint pass, uint num_bits) {
    uint shift = pass * kRadixSortDigitBits;
    return num_bits - shift < kRadixSortDigitBits ? num_bits - shift : kRadixSortDigitBits;
}

// The digit of `key` in pass `pass` of a sort of `num_bits` key bits: what the histograms
// count, in the sort and in producers that count for it
// (RadixSortScratch::sweep_histogram_written).
OPEN3D_SHADER_FUNC uint RadixSortDigit(uint key, uint pass, uint num_bits) {
    uint mask = (1u << RadixSortDigitBits(pass, num_bits)) - 1u;
    return (key >> (pass * kRadixSortDigitBits)) & mask;
}

// A sort's target block count as every rule below reads it: clamped to
// 1..kRadixSortTargetBlocks.
OPEN3D_SHADER_FUNC uint RadixSortClampedTarget(uint target_blocks) {
    uint target = target_blocks < 1u ? 1u : target_blocks;
    return target < kRadixSortTargetBlocks ? target : kRadixSortTargetBlocks;
}

// Most blocks RadixSortParamsFor gives any count <= max_count: up to target_blocks (clamped
// to 1..kRadixSortTargetBlocks) blocks of 256..kRadixSortBlockSize pairs, beyond that blocks
// of kRadixSortBlockSize. Sizes the status tables, and the rows a producer zeroes for a sort
// whose count it does not know yet.
OPEN3D_SHADER_FUNC uint RadixSortMaxBlocks(uint max_count, uint target_blocks) {
    uint target = RadixSortClampedTarget(target_blocks);
    uint smallest =
        max_count / kRadixSortWorkgroupSize + (max_count % kRadixSortWorkgroupSize == 0u ? 0u : 1u);
    uint largest =
        max_count / kRadixSortBlockSize + (max_count % kRadixSortBlockSize == 0u ? 0u : 1u);
    smallest = smallest < target ? smallest : target;
    return smallest > largest ? smallest : largest;
}

// The first pass's status rows a producer zeroes for a sort whose count it does not know yet
// (RadixSortScratch::sweep_histogram_written, docs/radix-sort.md): a sort of at most
// target x kRadixSortBlockSize keys has at most `target` blocks (RadixSortParamsFor), so
// rows [0, RadixSortSmallRows) cover it; a larger sort has blocks of kRadixSortBlockSize,
// and the producer workgroup that writes keys [begin, end) zeroes rows
// [RadixSortLargeRows.x, .y), those of the blocks its keys fall in past `target`: together the
// workgroups cover every block of the sort. Both stay below RadixSortMaxBlocks(max_count).
OPEN3D_SHADER_FUNC uint RadixSortSmallRows(uint max_count, uint target_blocks) {
    uint target = RadixSortClampedTarget(target_blocks);
    uint rows = RadixSortMaxBlocks(max_count, target_blocks);
    return target < rows ? target : rows;
}

OPEN3D_SHADER_FUNC uvec4 RadixSortLargeRows(uint begin, uint end, uint target_blocks) {
    uint target = RadixSortClampedTarget(target_blocks);
    uint first = begin / kRadixSortBlockSize;
    first = first > target ? first : target;
    uint last = begin < end ? (end - 1u) / kRadixSortBlockSize + 1u : 0u;
    return last > first ? uvec4(first, last, 0u, 0u) : uvec4(0u, 0u, 0u, 0u);  // or none
}

// ---- Radix sort parameters for an element count ----
// Clamps the count to max_count (kErrorCountsClamped) and chooses the block size: the
// fewest chunks of kRadixSortWorkgroupSize that keep the block count at or below
// target_blocks (clamped to 1..kRadixSortTargetBlocks), 1..kRadixSortItemsPerInvocation
// chunks. radix_sort_setup.comp calls it, and so does a producer that writes the sort's
// parameters itself (gaussian_dispatch_args.comp, and GaussianGeometryStage on the host for the
// depth sort, whose count is N), saving the sort its setup dispatch. No
// overflow: the host keeps max_count far below 2^32 - kRadixSortBlockSize. The per-block
// passes' grids are DispatchGridFor(num_blocks, max_groups_x): rows where the blocks pass
// the device's maxComputeWorkGroupCount[0].
OPEN3D_SHADER_FUNC RadixSortParams RadixSortParamsFor(uint count, uint max_count,
                                                      uint target_blocks, uint max_groups_x) {
    RadixSortParams p;
    p.flags = 0u;
    if (count > max_count) {
        count = max_count;
        p.flags = kErrorCountsClamped;
    }
    uint target = RadixSortClampedTarget(target_blocks);
    uint wave = kRadixSortWorkgroupSize * target;
    uint chunks = (count + wave - 1u) / wave;
    chunks = chunks < 1u ? 1u : chunks;
    chunks = chunks < kRadixSortItemsPerInvocation ? chunks : kRadixSortItemsPerInvocation;
    p.block_size = kRadixSortWorkgroupSize * chunks;
    p.num_blocks = (count + p.block_size - 1u) / p.block_size;
    uvec4 grid = DispatchGridFor(p.num_blocks, max_groups_x);
    p.dispatch_x = grid.x;
    p.dispatch_y = grid.y;
    p.dispatch_z = 1u;
    p.count = count;
    p.key_base = 0u;
    p.key_min = 0xFFFFFFFFu;
    p.key_max = 0u;
    p.range_passes = 0u;
    p.reserved0 = 0u;
    for (uint pass = 0u; pass < kRadixSortMaxPasses; ++pass) {
        p.pass_blocks[pass] = grid;
        p.pass_rows[pass] = uvec4(kRadixSortBins, 1u, 1u, 0u);
    }
    p.copy_blocks = uvec4(0u, grid.y, 1u, 0u);
    uint sweep_groups =
        p.num_blocks < kRadixSweepHistogramGroups ? p.num_blocks : kRadixSweepHistogramGroups;
    uvec4 sweep_grid = DispatchGridFor(sweep_groups, max_groups_x);
    p.sweep_histogram_grid = uvec4(sweep_grid.x, sweep_grid.y, 1u, sweep_groups);
    return p;
}

#ifdef __cplusplus
static_assert(kRadixSortBins == (1u << kRadixSortDigitBits));
static_assert(kRadixSortWorkgroupSize == kRadixSortBins, "one invocation per bin");
static_assert(kRadixSortBlockSize == kRadixSortWorkgroupSize * kRadixSortItemsPerInvocation);
static_assert(kRadixSortWorkgroupSize % kRadixSortMaxSubgroups == 0);

static_assert(sizeof(RadixSortParams) == 208);
static_assert(offsetof(RadixSortParams, sweep_histogram_grid) == 192);
static_assert(sizeof(RadixSweepState) == 4 * (kRadixSortMaxPasses * kRadixSortBins + 8));
static_assert(offsetof(RadixSweepState, next_block) == 4 * kRadixSortMaxPasses * kRadixSortBins);
static_assert(kRadixSweepFlagAggregate > kRadixSweepValueMask &&
              (kRadixSweepFlagAggregate & kRadixSweepFlagInclusive) == 0u);
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

static_assert(sizeof(RadixSortPushConstants) == 56);
static_assert(offsetof(RadixSortPushConstants, target_blocks) == 16);
static_assert(offsetof(RadixSortPushConstants, shift) == 0);
static_assert(offsetof(RadixSortPushConstants, digit_bits) == 4);
static_assert(offsetof(RadixSortPushConstants, count_index) == 8);
static_assert(offsetof(RadixSortPushConstants, max_count) == 12);
static_assert(offsetof(RadixSortPushConstants, drop_max_keys) == 20);
static_assert(offsetof(RadixSortPushConstants, key_range) == 24);
static_assert(offsetof(RadixSortPushConstants, num_passes) == 28);
static_assert(offsetof(RadixSortPushConstants, values_only) == 32);
static_assert(offsetof(RadixSortPushConstants, max_groups_x) == 36);
static_assert(offsetof(RadixSortPushConstants, num_bits) == 40);
static_assert(offsetof(RadixSortPushConstants, sweep) == 44);
static_assert(offsetof(RadixSortPushConstants, run_keys) == 48);
static_assert(offsetof(RadixSortPushConstants, run_offset) == 52);
static_assert(offsetof(RadixSortParams, reserved0) == 44);

}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_RADIX_SORT_CONTRACT_H
