#version 460
// Pass 3 of a digit (the multi-pass sort): moves every pair of a block to its sorted
// position. The block ranks its pairs (radix_sort_rank.glsl); the scan left its first
// output index within each digit, so a pair's output index is s_out_shift[digit] + its
// block-local position. Three barriers per block, where a scan across subgroups after every
// chunk of 256 pairs needs four per chunk (docs/perf/h100.md).
// Writing (kLocalCapacity > 1, where shared memory allows): the pairs go to shared memory at
// their local positions and the block is written out in sorted order at the end, so each
// digit's run of the block is one contiguous write. Otherwise (lavapipe's 32 KiB) every
// pair is written straight from its register, about one pair per digit and memory segment,
// about twice as slow on NVIDIA (docs/perf/h100.md "Radix sort").
// Dropping (a first pass with drop_max_keys): pairs with key kRadixSortDroppedKey take no
// rank and are not written, so the block's kept pairs are packed from its output offsets.
// Stable (blocks take their offsets in block order); correct for any subgroup size of at
// least kRadixSortWorkgroupSize / kRadixSortMaxSubgroups lanes.
#extension GL_GOOGLE_include_directive : require
#include "radix_sort_common.glsl"

layout(local_size_x = kRadixSortWorkgroupSize) in;

layout(std430, set = 0, binding = kRadixSortParamsBinding) readonly buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortKeysInBinding) readonly buffer KeysInBlock {
    uint keys_in[];
};
layout(std430, set = 0, binding = kRadixSortValuesInBinding) readonly buffer ValuesInBlock {
    uint values_in[];
};
layout(std430, set = 0, binding = kRadixSortKeysOutBinding) writeonly buffer KeysOutBlock {
    uint keys_out[];
};
layout(std430, set = 0, binding = kRadixSortValuesOutBinding) writeonly buffer ValuesOutBlock {
    uint values_out[];
};
layout(std430, set = 0, binding = kRadixSortHistogramBinding) readonly buffer HistogramBlock {
    uint histogram[];
};

// kRadixSortBlockSize when the block is reordered in shared memory, else 1 (RadixSort.cpp).
layout(constant_id = kSpecRadixSortLocalCapacity) const uint kLocalCapacity = 1u;

shared uint s_first[kRadixSortBins];      // block-local position of each digit's first pair
shared uint s_out_shift[kRadixSortBins];  // output index - block-local position, per digit
shared uint s_keys[kLocalCapacity];  // the block in sorted order
shared uint s_values[kLocalCapacity];

#include "radix_sort_rank.glsl"

void main() {
    uint block = FlatWorkGroupIndex();
    if (block >= params.num_blocks) return;  // a spare workgroup of the grid's last row
    g_key_base = params.key_base;
    InitScanSlot();
    uint local = gl_LocalInvocationIndex;
    uint count = params.count;
    uint num_blocks = params.num_blocks;
    uint block_kept;  // pairs of this block the histogram counted (all but dropped keys)
    bool write_keys = WritesKeys(params.range_passes != 0u ? params.range_passes : pc.num_passes);

    // The scan left the block's first output index within each digit; the block's count of
    // a digit is the next block's index minus its own (the digit's total after the last
    // block). Invocation g_slot handles digit g_slot, so both scans run over digits.
    {
        uint row = kRadixSortBins + g_slot * num_blocks;
        uint first = histogram[row + block];
        uint next = block + 1u < num_blocks ? histogram[row + block + 1u] : histogram[g_slot];
        uint local_first = WorkgroupExclusiveAdd(next - first, block_kept);
        uint total;
        uint digit_base = WorkgroupExclusiveAdd(histogram[g_slot], total);
        s_first[g_slot] = local_first;
        s_out_shift[g_slot] = digit_base + first - local_first;
    }
    uint chunks = params.block_size / kRadixSortWorkgroupSize;  // uniform, 1..8
    uint block_begin = block * params.block_size;
    RankBlock(block_begin, min(block_begin + params.block_size, count), chunks);
    ScanSubgroupCounts();
    for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        if (k >= chunks) break;
        if ((g_kept & (1u << k)) == 0u) continue;
        uint digit = DigitOf(g_keys[k]);
        uint position = LocalPosition(k, s_first[digit]);
        if (kLocalCapacity > 1u) {
            s_keys[position] = g_keys[k];
            s_values[position] = g_values[k];
        } else {
            if (write_keys) keys_out[s_out_shift[digit] + position] = g_keys[k];
            values_out[s_out_shift[digit] + position] = g_values[k];
        }
    }
    if (kLocalCapacity == 1u) return;
    barrier();
    // The whole block is in s_keys and s_values.
    for (uint i = local; i < block_kept; i += kRadixSortWorkgroupSize) {
        uint key = s_keys[i];
        uint out_index = s_out_shift[DigitOf(key)] + i;
        if (write_keys) keys_out[out_index] = key;
        values_out[out_index] = s_values[i];
    }
}
