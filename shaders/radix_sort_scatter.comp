#version 460
// Pass 3 of a digit: moves every pair of a block to its sorted position.
// Ranking: the block is processed in chunks of kRadixSortWorkgroupSize pairs, one per
// invocation in scan-slot order. Each subgroup ranks its pairs by digit with ballots (the
// lanes holding the same digit are the intersection of one ballot per digit bit), the
// per-subgroup digit counts are scanned across subgroups in shared memory, and every pair
// gets its block-local sorted position: the digit's start in the block + earlier chunks'
// and subgroups' count of the digit + rank among its subgroup's equal digits. The block's
// output index of that position is s_out_shift[digit] + position.
// Writing (kLocalCapacity > 1, where shared memory allows): the pairs go to shared memory at
// their local positions and the block is written out in sorted order at the end, so each
// digit's run of the block is one contiguous write. Otherwise (lavapipe's 32 KiB) every
// pair is written straight from its chunk, about one pair per digit and memory segment:
// on the H100 that took 250 us per pass of the grid's 6.1M-key depth sort, against 130
// with the local reorder.
// Stability: pairs are loaded in scan-slot order (subgroups by gl_SubgroupID, lanes by
// gl_SubgroupInvocationID, the order of ballot bits), earlier subgroups take lower
// positions, chunks run in index order and blocks take their offsets in block order, so
// equal digits keep their input order. Correct for any subgroup size of at least
// kRadixSortWorkgroupSize / kRadixSortMaxSubgroups lanes.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require
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

shared uint s_next[kRadixSortBins];       // next block-local position per digit
shared uint s_out_shift[kRadixSortBins];  // output index - block-local position, per digit
// [subgroup][digit / 2]: the subgroup's count of each digit in the chunk, then the count of
// the earlier subgroups (the exclusive scan); digit d sits in half d % 2 of word d / 2.
// Counts stay <= kRadixSortWorkgroupSize, so the halves never carry into each other.
shared uint s_counts[kMaxSubgroups * kPairWords];
shared uint s_totals[kPairWords];  // the chunk's count of each digit, packed the same way
shared uint s_keys[kLocalCapacity];  // the block in sorted order
shared uint s_values[kLocalCapacity];

uint HalfOf(uint word, uint digit) {
    return (word >> ((digit & 1u) * 16u)) & 0xFFFFu;
}

void main() {
    InitScanSlot();
    uint local = gl_LocalInvocationIndex;
    uint count = params.count;
    uint num_blocks = params.num_blocks;
    uint block = gl_WorkGroupID.x;

    // The scan left the block's first output index within each digit; the block's count of
    // a digit is the next block's index minus its own (the digit's total after the last
    // block). Invocation g_slot handles digit g_slot, so both scans run over digits.
    {
        uint row = kRadixSortBins + g_slot * num_blocks;
        uint first = histogram[row + block];
        uint next = block + 1u < num_blocks ? histogram[row + block + 1u] : histogram[g_slot];
        uint total;
        uint local_first = WorkgroupExclusiveAdd(next - first, total);
        uint digit_base = WorkgroupExclusiveAdd(histogram[g_slot], total);
        s_next[g_slot] = local_first;
        s_out_shift[g_slot] = digit_base + first - local_first;
    }
    uint words = gl_NumSubgroups * kPairWords;
    for (uint w = local; w < words; w += kRadixSortWorkgroupSize) s_counts[w] = 0u;
    barrier();
    uint row = gl_SubgroupID * kPairWords;

    uint block_size = params.block_size;
    uint block_begin = block * block_size;
    // Each chunk's pair is loaded one chunk ahead, so the load's latency overlaps the
    // ranking of the previous chunk instead of stalling every chunk.
    uint block_end = min(block_begin + block_size, count);
    uint next_index = block_begin + g_slot;
    uint next_key = next_index < block_end ? keys_in[next_index] : 0u;
    uint next_value = next_index < block_end ? values_in[next_index] : 0u;
    for (uint chunk_begin = block_begin; chunk_begin < block_end;
         chunk_begin += kRadixSortWorkgroupSize) {  // uniform over the workgroup
        uint index = next_index;
        bool valid = index < block_end;
        uint key = next_key;
        uint value = next_value;
        next_index = index + kRadixSortWorkgroupSize;
        if (next_index < block_end) {
            next_key = keys_in[next_index];
            next_value = values_in[next_index];
        }
        uint digit = DigitOf(key);

        // Valid lanes of this subgroup with the same digit.
        uvec4 peers = subgroupBallot(valid);
        for (uint b = 0u; b < pc.digit_bits; ++b) {
            bool bit = ((digit >> b) & 1u) != 0u;
            uvec4 ballot = subgroupBallot(bit);
            peers &= bit ? ballot : ~ballot;
        }
        uint rank = subgroupBallotExclusiveBitCount(peers);
        if (valid && rank == 0u) {
            atomicAdd(s_counts[row + (digit >> 1u)],
                      subgroupBallotBitCount(peers) << ((digit & 1u) * 16u));
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
            s_totals[local] = running;
        }
        barrier();
        if (valid) {
            uint position = s_next[digit] + HalfOf(s_counts[row + (digit >> 1u)], digit) + rank;
            if (kLocalCapacity > 1u) {
                s_keys[position] = key;
                s_values[position] = value;
            } else {
                keys_out[s_out_shift[digit] + position] = key;
                values_out[s_out_shift[digit] + position] = value;
            }
        }
        barrier();  // every offset and count was read before they change
        s_next[local] += HalfOf(s_totals[local >> 1u], local);
        for (uint w = local; w < words; w += kRadixSortWorkgroupSize) s_counts[w] = 0u;
        barrier();
    }
    if (kLocalCapacity == 1u) return;
    // The chunk loop ended with a barrier: the whole block is in s_keys and s_values.
    for (uint i = local; i < block_end - block_begin; i += kRadixSortWorkgroupSize) {
        uint key = s_keys[i];
        uint out_index = s_out_shift[DigitOf(key)] + i;
        keys_out[out_index] = key;
        values_out[out_index] = s_values[i];
    }
}
