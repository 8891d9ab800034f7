// A block's stable ranking by one digit, shared by both scatters (radix_sort_scatter.comp,
// radix_sort_sweep_scatter.comp; docs/radix-sort.md).
// Each subgroup owns a contiguous run of the block (lanes x chunks pairs; lane l holds pairs
// l, l + lanes, ... of it) and ranks its pairs step by step with ballots (the lanes holding
// the same digit are the intersection of one ballot per digit bit), keeping a running count
// per digit in shared memory: a pair's rank in its subgroup is that count before its step
// plus its rank among the step's equal digits. ScanSubgroupCounts then turns the counts into
// the earlier subgroups' count of each digit, so a pair's block-local sorted position is the
// digit's start in the block + that count + its rank (LocalPosition).
// Stability: subgroups own runs in scan-slot order (gl_SubgroupID), a subgroup ranks its run
// in element order (steps in order, lanes by gl_SubgroupInvocationID, the order of ballot
// bits) and earlier subgroups take lower positions. Needs InitScanSlot() first.
#ifndef OPEN3D_RADIX_SORT_RANK_GLSL
#define OPEN3D_RADIX_SORT_RANK_GLSL

#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require

const uint kPairWords = kRadixSortBins / 2u;  // two 16-bit digit counters per word

// [subgroup][digit / 2]: the subgroup's running count of each digit, then the count of the
// earlier subgroups (ScanSubgroupCounts); digit d sits in half d % 2 of word d / 2. Counts
// stay <= kRadixSortBlockSize, so the halves never carry into each other.
shared uint s_counts[kMaxSubgroups * kPairWords];

// This invocation's pairs: all loaded at once, so that the loads are in flight together.
uint g_keys[kRadixSortItemsPerInvocation];
uint g_values[kRadixSortItemsPerInvocation];
uint g_ranks[kRadixSortItemsPerInvocation];
uint g_kept;  // bit k: pair k is in the block and not a dropped key

uint HalfOf(uint word, uint digit) {
    return (word >> ((digit & 1u) * 16u)) & 0xFFFFu;
}

// Loads this invocation's pairs of [block_begin, block_end) (chunks of
// kRadixSortWorkgroupSize per block) and ranks them within their subgroup. Ends with a
// barrier: s_counts then holds every subgroup's count of each digit.
void RankBlock(uint block_begin, uint block_end, uint chunks) {
    uint local = gl_LocalInvocationIndex;
    uint words = gl_NumSubgroups * kPairWords;
    for (uint w = local; w < words; w += kRadixSortWorkgroupSize) s_counts[w] = 0u;
    barrier();
    uint row = gl_SubgroupID * kPairWords;
    uint lanes = g_subgroup_lanes;
    uint first = block_begin + g_subgroup_first_slot * chunks + (g_slot - g_subgroup_first_slot);
    for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        uint index = first + k * lanes;
        bool valid = k < chunks && index < block_end;
        g_keys[k] = valid ? keys_in[index] : 0u;
        g_values[k] = valid ? values_in[index] : 0u;
    }
    g_kept = 0u;
    for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        if (k >= chunks) break;  // uniform
        bool valid = first + k * lanes < block_end && IsKept(g_keys[k]);
        if (valid) g_kept |= 1u << k;
        uint digit = DigitOf(g_keys[k]);
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
        g_ranks[k] = HalfOf(subgroupShuffle(before, leader), digit) + rank;
    }
    barrier();
}

// Exclusive scan of s_counts over subgroups, both digits of a word at once; invocation w <
// kPairWords returns the block's totals of digits 2w and 2w + 1 (halves of one word).
// Ends with a barrier.
uint ScanSubgroupCounts() {
    uint local = gl_LocalInvocationIndex;
    uint running = 0u;
    if (local < kPairWords) {
        for (uint s = 0u; s < gl_NumSubgroups; ++s) {
            uint w = s * kPairWords + local;
            uint c = s_counts[w];
            s_counts[w] = running;
            running += c;
        }
    }
    barrier();
    return running;
}

// Block-local sorted position of this invocation's pair k, given the block-local position
// of the first pair of each digit.
uint LocalPosition(uint k, uint digit_first) {
    uint digit = DigitOf(g_keys[k]);
    return digit_first + HalfOf(s_counts[gl_SubgroupID * kPairWords + (digit >> 1u)], digit) +
           g_ranks[k];
}

#endif  // OPEN3D_RADIX_SORT_RANK_GLSL
