#version 460
// Pass 3 of a digit: moves every pair of a block to its sorted position. The block is
// processed in chunks of kRadixSortWorkgroupSize pairs, one per invocation in scan-slot
// order. Each subgroup ranks its pairs by digit with ballots (the lanes holding the same
// digit are the intersection of one ballot per digit bit), the per-subgroup digit counts
// are scanned across subgroups in shared memory, and every pair is written straight to
// digit offset + earlier subgroups' count + rank among its subgroup's equal digits.
// Three barriers per chunk; the earlier two-round 4-bit split needed ten and ran the H100's
// 6M-key depth sort at a third of this speed.
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

shared uint s_digit_offset[kRadixSortBins];  // next output index per digit
// [subgroup][digit / 2]: the subgroup's count of each digit in the chunk, then the count of
// the earlier subgroups (the exclusive scan); digit d sits in half d % 2 of word d / 2.
// Counts stay <= kRadixSortWorkgroupSize, so the halves never carry into each other.
shared uint s_counts[kRadixSortMaxSubgroups * kPairWords];
shared uint s_totals[kPairWords];  // the chunk's count of each digit, packed the same way

uint HalfOf(uint word, uint digit) {
    return (word >> ((digit & 1u) * 16u)) & 0xFFFFu;
}

void main() {
    InitScanSlot();
    uint local = gl_LocalInvocationIndex;
    uint count = params.count;
    uint num_blocks = params.num_blocks;
    uint block = gl_WorkGroupID.x;

    // Output offset of this block per digit = all smaller digits + earlier blocks' digit.
    {
        uint total;
        uint digit_base = WorkgroupExclusiveAdd(histogram[g_slot], total);
        s_digit_offset[g_slot] =
                digit_base + histogram[kRadixSortBins + g_slot * num_blocks + block];
    }
    uint words = gl_NumSubgroups * kPairWords;
    for (uint w = local; w < words; w += kRadixSortWorkgroupSize) s_counts[w] = 0u;
    barrier();
    uint row = gl_SubgroupID * kPairWords;

    uint block_size = params.block_size;
    uint block_begin = block * block_size;
    for (uint chunk_begin = block_begin; chunk_begin < block_begin + block_size;
         chunk_begin += kRadixSortWorkgroupSize) {
        if (chunk_begin >= count) break;  // uniform over the workgroup
        uint index = chunk_begin + g_slot;
        bool valid = index < count;
        uint key = valid ? keys_in[index] : 0u;
        uint value = valid ? values_in[index] : 0u;
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
            uint out_index =
                    s_digit_offset[digit] + HalfOf(s_counts[row + (digit >> 1u)], digit) + rank;
            keys_out[out_index] = key;
            values_out[out_index] = value;
        }
        barrier();  // every offset and count was read before they change
        s_digit_offset[local] += HalfOf(s_totals[local >> 1u], local);
        for (uint w = local; w < words; w += kRadixSortWorkgroupSize) s_counts[w] = 0u;
        barrier();
    }
}
