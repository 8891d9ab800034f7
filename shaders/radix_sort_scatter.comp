#version 460
// Pass 3 of a digit: moves every pair of a block to its sorted position.
// Ranking: each subgroup owns a contiguous run of the block (lanes x chunks pairs; lane l
// holds pairs l, l + lanes, ... of it) and ranks its pairs step by step with ballots (the
// lanes holding the same digit are the intersection of one ballot per digit bit), keeping
// a running count per digit in shared memory: a pair's rank in its subgroup is that count
// before its step plus its rank among the step's equal digits. One scan across subgroups
// then gives each pair its block-local sorted position: the digit's start in the block +
// the earlier subgroups' count of the digit + its rank in the subgroup. The block's output
// index of that position is s_out_shift[digit] + position. Three barriers per block, where a
// scan across subgroups after every chunk of 256 pairs needs four per chunk (docs/perf/h100.md).
// Writing (kLocalCapacity > 1, where shared memory allows): the pairs go to shared memory at
// their local positions and the block is written out in sorted order at the end, so each
// digit's run of the block is one contiguous write. Otherwise (lavapipe's 32 KiB) every
// pair is written straight from its register, about one pair per digit and memory segment,
// about twice as slow on NVIDIA (docs/perf/h100.md "Radix sort").
// Dropping (a first pass with drop_max_keys): pairs with key kRadixSortDroppedKey take no
// rank and are not written, so the block's kept pairs are packed from its output offsets.
// Stability: subgroups own runs in scan-slot order (gl_SubgroupID), a subgroup ranks its
// run in element order (steps in order, lanes by gl_SubgroupInvocationID, the order of
// ballot bits), earlier subgroups take lower positions and blocks take their offsets in
// block order, so equal digits keep their input order. Correct for any subgroup size of at
// least kRadixSortWorkgroupSize / kRadixSortMaxSubgroups lanes.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
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

const uint kPairWords = kRadixSortBins / 2u;  // two 16-bit digit counters per word

// kRadixSortBlockSize when the block is reordered in shared memory, else 1 (RadixSort.cpp).
layout(constant_id = kSpecRadixSortLocalCapacity) const uint kLocalCapacity = 1u;

shared uint s_first[kRadixSortBins];      // block-local position of each digit's first pair
shared uint s_out_shift[kRadixSortBins];  // output index - block-local position, per digit
// [subgroup][digit / 2]: the subgroup's running count of each digit, then the count of the
// earlier subgroups (the exclusive scan); digit d sits in half d % 2 of word d / 2. Counts
// stay <= kRadixSortBlockSize, so the halves never carry into each other.
shared uint s_counts[kMaxSubgroups * kPairWords];
shared uint s_keys[kLocalCapacity];  // the block in sorted order
shared uint s_values[kLocalCapacity];

uint HalfOf(uint word, uint digit) {
    return (word >> ((digit & 1u) * 16u)) & 0xFFFFu;
}

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
    uint words = gl_NumSubgroups * kPairWords;
    for (uint w = local; w < words; w += kRadixSortWorkgroupSize) s_counts[w] = 0u;
    barrier();
    uint row = gl_SubgroupID * kPairWords;

    // This subgroup's run: lanes x chunks pairs from the position of its first scan slot.
    uint chunks = params.block_size / kRadixSortWorkgroupSize;  // uniform, 1..8
    uint block_begin = block * params.block_size;
    uint block_end = min(block_begin + params.block_size, count);
    uint lanes = g_subgroup_lanes;
    uint first = block_begin + g_subgroup_first_slot * chunks + (g_slot - g_subgroup_first_slot);
    // All loads first, so that they are in flight together.
    uint keys[kRadixSortItemsPerInvocation];
    uint values[kRadixSortItemsPerInvocation];
    uint ranks[kRadixSortItemsPerInvocation];
    uint kept = 0u;  // bit k: pair k is in the block and not a dropped key
    for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        uint index = first + k * lanes;
        bool valid = k < chunks && index < block_end;
        keys[k] = valid ? keys_in[index] : 0u;
        values[k] = valid ? values_in[index] : 0u;
    }
    for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        if (k >= chunks) break;  // uniform
        bool valid = first + k * lanes < block_end && IsKept(keys[k]);
        if (valid) kept |= 1u << k;
        uint digit = DigitOf(keys[k]);
        // Valid lanes of this subgroup with the same digit.
        uvec4 peers = subgroupBallot(valid);
        for (uint b = 0u; b < pc.digit_bits; ++b) {
            bool bit = ((digit >> b) & 1u) != 0u;
            uvec4 ballot = subgroupBallot(bit);
            peers &= bit ? ballot : ~ballot;
        }
        uint rank = subgroupBallotExclusiveBitCount(peers);
        uint before = 0u;
        if (valid && rank == 0u) {
            before = atomicAdd(s_counts[row + (digit >> 1u)],
                               subgroupBallotBitCount(peers) << ((digit & 1u) * 16u));
        }
        // The first of the peers added their count; every peer needs the count before it.
        uint leader = valid ? subgroupBallotFindLSB(peers) : gl_SubgroupInvocationID;
        ranks[k] = HalfOf(subgroupShuffle(before, leader), digit) + rank;
    }
    barrier();
    // Exclusive scan over subgroups, both digits of a word at once.
    if (local < kPairWords) {
        uint running = 0u;
        for (uint s = 0u; s < gl_NumSubgroups; ++s) {
            uint w = s * kPairWords + local;
            uint c = s_counts[w];
            s_counts[w] = running;
            running += c;
        }
    }
    barrier();
    for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        if (k >= chunks) break;
        if ((kept & (1u << k)) == 0u) continue;
        uint digit = DigitOf(keys[k]);
        uint position = s_first[digit] + HalfOf(s_counts[row + (digit >> 1u)], digit) + ranks[k];
        if (kLocalCapacity > 1u) {
            s_keys[position] = keys[k];
            s_values[position] = values[k];
        } else {
            if (write_keys) keys_out[s_out_shift[digit] + position] = keys[k];
            values_out[s_out_shift[digit] + position] = values[k];
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
