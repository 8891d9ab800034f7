#version 460
// Geometry stage, the exact order on GPUs (the one-sweep sorts): the scan of the tile
// counts in depth order, the capacity cut and the emit in one dispatch, where the scan
// levels, the dispatch-args pass and gaussian_emit.comp took four or more dependent ones.
// A workgroup takes the next block of kEmitWorkgroupSize list slots in the order
// workgroups start (a ticket), sums their counts, and finds the entries of the blocks
// before it by decoupled look-back (as radix_sort_sweep_scatter.comp does per digit);
// each slot then knows its [begin, end) and emits whole or not at all.
// The capacity cut is the dispatch-args pass's rule: splats emit front to back and the
// first one whose end passes the capacity drops, with every splat after it. That splat,
// the only slot with begin <= capacity < end, writes entry_count = begin, the flags and
// the tile sort's parameters; when everything fits, the last slot writes them.
// Counts saturate at kRadixSweepValueMask (2^30 - 1), above any capacity the sorts allow,
// so a saturated offset reads as "does not fit" (requested_entries saturates there too).
// Needs the look-back's forward progress: the recorder uses it where the sorts run the one
// sweep (GPUs; lavapipe in tests with one thread, where workgroups run in ticket order).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "GaussianSplatTileListContract.h"
#include "gaussian_device_address.glsl"

layout(local_size_x = kEmitWorkgroupSize) in;

layout(constant_id = kSpecEmitChainedOddBlocksAggregateOnly) const uint kOddBlocksAggregateOnly = 0u;

layout(push_constant, std430) uniform PushConstantsBlock {
    GaussianDispatchArgsPushConstants pc;
    layout(offset = kGeometryAddressesPushOffset) GaussianGeometryAddresses addresses;
};

layout(std430, set = 0, binding = kGeometryStageViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(std430, set = 0, binding = kGeometryStageCountersBinding) buffer CountersBlock {
    GaussianGeometryStageCounters counters;
};
layout(std430, set = 0, binding = kGeometryStageSplatIndexBinding) readonly buffer SplatIndexBlock {
    uint splat_indices[];
};
// The ticket and the blocks' look-back status words (kEmitChainedTicketWord,
// kEmitChainedStatusBase), read and written with atomics.
layout(std430, set = 0, binding = kGeometryStageScanBinding) coherent buffer StatusBlock {
    uint status[];
};
layout(std430, set = 0, binding = kGeometryStageTileCountsBinding) readonly buffer TileCountsBlock {
    uint tile_counts[];  // by splat index, written by the projection for visible splats
};
layout(std430, set = 0, binding = kGeometryStageEntryKeysBinding) writeonly buffer EntryKeysBlock {
    uint entry_keys[];
};
layout(std430, set = 0, binding = kGeometryStageEntryValuesBinding) writeonly buffer EntryValuesBlock {
    uint entry_values[];
};
layout(std430, set = 0, binding = kGeometryStageSortParamsBinding) writeonly buffer SortParamsBlock {
    RadixSortParams sort_params;
};

// The tile sort's one-sweep state: this pass adds its digit counts, and zeroes the first
// pass's status rows, in place of the sort's histogram dispatch
// (RadixSortScratch::sweep_histogram_written).
layout(std430, set = 0, binding = kGeometryStageTileSortStateBinding) buffer TileSortStateBlock {
    RadixSweepState tile_sort_state;
};
layout(std430, set = 0, binding = kGeometryStageSortStatusBinding) writeonly buffer SortStatusBlock {
    uint sort_status[];
};
// The composite's state: its header (zeroed here) and each tile's [begin, end) from word
// kBinRangesWordOffset, set here to the empty (0xFFFFFFFF, 0) that the tile sort's last pass
// lowers and raises (its run bounds).
layout(std430, set = 0, binding = kGeometryStageTileRangesBinding) writeonly buffer TileRangesBlock {
    uint tile_ranges[];
};

// The tile sort's digit counts of this workgroup's entries, pass-major. The first pass's
// come from s_low_diff instead, except the filler keys'.
shared uint s_digit_counts[kRadixSortMaxPasses * kRadixSortBins];
// The first pass's counts as a difference array (+1 where a run of low digits starts, -1
// past where it ends; its prefix sums are the counts) and the whole cycles of 2^bits keys
// every digit received. A row span's keys are consecutive tiles, so it adds a few words
// instead of one shared atomic per key: per key, the lanes of a subgroup, whose splats
// cover nearby rows, queued on the same bins of the later passes.
shared uint s_low_diff[kRadixSortBins + 1u];
shared uint s_low_cycles;

// The tile sort's passes over view.tile_bits key bits (RadixSort::GetNumPasses).
uint TileSortPasses() {
    return (view.tile_bits + kRadixSortDigitBits - 1u) / kRadixSortDigitBits;
}

// Counts the keys first .. first + count - 1 (tiles, below 2^tile_bits).
void CountTileRun(uint first, uint count) {
    // First pass: the keys take `count` consecutive digits modulo 2^bits.
    uint bits = RadixSortDigitBits(0u, view.tile_bits);
    uint m = 1u << bits;
    uint cycles = count >> bits;
    uint rest = count & (m - 1u);
    if (cycles != 0u) atomicAdd(s_low_cycles, cycles);
    if (rest != 0u) {
        uint d = first & (m - 1u);
        atomicAdd(s_low_diff[d], 1u);
        if (d + rest <= m) {
            atomicAdd(s_low_diff[d + rest], 0xFFFFFFFFu);
        } else {  // wraps past the last digit
            atomicAdd(s_low_diff[0], 1u);
            atomicAdd(s_low_diff[d + rest - m], 0xFFFFFFFFu);
        }
    }
    // Later passes: each digit block of 2^shift keys the run crosses gets its overlap.
    uint passes = TileSortPasses();
    uint end = first + count;
    for (uint p = 1u; p < passes; ++p) {
        uint shift = p * kRadixSortDigitBits;
        for (uint t = first; t < end;) {
            uint next = min(((t >> shift) + 1u) << shift, end);
            atomicAdd(s_digit_counts[p * kRadixSortBins + RadixSortDigit(t, p, view.tile_bits)],
                      next - t);
            t = next;
        }
    }
}

void CountFillerKey() {
    uint passes = TileSortPasses();
    for (uint p = 0u; p < passes; ++p) {
        uint digit = RadixSortDigit(0xFFFFFFFFu, p, view.tile_bits);
        atomicAdd(s_digit_counts[p * kRadixSortBins + digit], 1u);
    }
}
#define OPEN3D_EMIT_COUNT_RUN(first, count) CountTileRun(first, count)
#define OPEN3D_EMIT_COUNT_FILLER() CountFillerKey()

#include "gaussian_emit_entries.glsl"

shared uint s_block;
shared uint s_prefix;  // entries of the blocks before this one
shared uint s_block_total;
// Per subgroup: its lanes (for the slot order), then its sums in the workgroup scans.
shared uint s_subgroup_lanes[kEmitWorkgroupSize];
shared uint s_subgroup_sums[kEmitWorkgroupSize];

#include "gaussian_list_count.glsl"

// The frame's entry count, flags and the tile sort's parameters, from the one slot that
// decides them.
void WriteEntryCount(uint entries, uint flags) {
    counters.entry_count = entries;
    if (flags != 0u) atomicOr(counters.error_flags, flags);
    sort_params =
        RadixSortParamsFor(entries, pc.sort_max_count, pc.sort_target_blocks, pc.max_groups_x);
}

// Block `block`'s prefix, found by the workgroup's first subgroup: its own total published
// as an aggregate, then the earlier blocks' words read a subgroup-wide window at a time (lane
// i reads block back - i) and added up to the nearest one that holds an inclusive prefix,
// then its own inclusive prefix. A window with a word still 0 below that point (its block
// has started, so it will publish) is read again. One word at a time, a block far from the
// last inclusive prefix waited one global round trip per block: with every block started
// at once the last of n blocks walked about n / 2 words (docs/perf/h100-chained-frame.md).
uint LookBack(uint block, uint own) {
    uint word = kEmitChainedStatusBase + block;
    bool first_lane = gl_SubgroupInvocationID == 0u;
    if (block == 0u) {
        if (first_lane) atomicExchange(status[word], kRadixSweepFlagInclusive | own);
        return 0u;
    }
    if (first_lane) atomicExchange(status[word], kRadixSweepFlagAggregate | own);
    uint lane = gl_SubgroupInvocationID;
    uint prefix = 0u;
    uint back = block - 1u;  // the window's newest block
    while (true) {
        // Lanes past block 0 read as an inclusive 0 (block 0 always publishes one anyway).
        uint s = lane <= back ? atomicAdd(status[kEmitChainedStatusBase + back - lane], 0u)
                              : kRadixSweepFlagInclusive;
        bool inclusive = (s & kRadixSweepFlagInclusive) != 0u;
        uvec4 inclusive_lanes = subgroupBallot(inclusive);
        bool found = subgroupBallotBitCount(inclusive_lanes) != 0u;
        uint limit = found ? subgroupBallotFindLSB(inclusive_lanes) : gl_SubgroupSize - 1u;
        bool pending = s == 0u && lane <= limit;  // not published yet
        if (subgroupBallotBitCount(subgroupBallot(pending)) != 0u) continue;
        uint value = lane <= limit ? (s & kRadixSweepValueMask) : 0u;
        // A saturating sum: a subgroup's values of up to 2^30 - 1 can pass 2^32, their
        // halves cannot.
        uint high = subgroupAdd(value >> 16u);
        uint low = subgroupAdd(value & 0xFFFFu);
        uint sum = high > (kRadixSweepValueMask >> 16u)
                           ? kRadixSweepValueMask
                           : min(high * 65536u + low, kRadixSweepValueMask);
        prefix = min(prefix + sum, kRadixSweepValueMask);
        if (found) break;
        back -= gl_SubgroupSize;  // no inclusive word: every lane read a real block
    }
    if (first_lane && (kOddBlocksAggregateOnly == 0u || (block & 1u) == 0u)) {
        atomicExchange(status[word],
                       kRadixSweepFlagInclusive | min(prefix + own, kRadixSweepValueMask));
    }
    return prefix;
}

// Every tile's range starts empty, spread over all workgroups of the dispatch (the recorder
// adds spare ones where the blocks are fewer than the tiles need), and the composite state's
// header (its tile counter) starts at zero (CompositeStageInputs::state_zeroed).
void ClearTileRanges(uint ticket) {
    uint local = gl_LocalInvocationIndex;
    uint num_tiles = view.tiles_x * view.tiles_y;
    uint stride = gl_NumWorkGroups.x * gl_NumWorkGroups.y * kEmitWorkgroupSize;
    if (ticket == 0u && local < kBinRangesWordOffset) tile_ranges[local] = 0u;
    for (uint t = ticket * kEmitWorkgroupSize + local; t < num_tiles; t += stride) {
        tile_ranges[kBinRangesWordOffset + 2u * t] = 0xFFFFFFFFu;
        tile_ranges[kBinRangesWordOffset + 2u * t + 1u] = 0u;
    }
}

// The rows of status table 0 that the tile sort's first pass reads, zeroed before it runs
// (the depth sort used the same words) without knowing the entry count yet: rows
// [0, RadixSortSmallRows) by every workgroup of the dispatch together, spares included, and
// by each workgroup the rows RadixSortLargeRows gives for its own kept entries.
void ZeroSmallSortRows(uint ticket) {
    uint rows = RadixSortSmallRows(view.entry_capacity, pc.sort_target_blocks);
    uint stride = gl_NumWorkGroups.x * gl_NumWorkGroups.y * kEmitWorkgroupSize;
    for (uint i = ticket * kEmitWorkgroupSize + gl_LocalInvocationIndex; i < rows * kRadixSortBins;
         i += stride) {
        sort_status[i] = 0u;
    }
}

void ZeroLargeSortRows(uint begin, uint end) {
    uvec4 rows = RadixSortLargeRows(begin, end, pc.sort_target_blocks);
    for (uint i = rows.x * kRadixSortBins + gl_LocalInvocationIndex; i < rows.y * kRadixSortBins;
         i += kEmitWorkgroupSize) {
        sort_status[i] = 0u;
    }
}

// The inclusive sum of `value` over the workgroup in slot order (subgroups by gl_SubgroupID,
// lanes by gl_SubgroupInvocationID), and the workgroup's total: a subgroup scan and one
// barrier, where a scan in shared memory by local index took sixteen. The caller puts a
// barrier between two calls (s_subgroup_sums is reused).
uint WorkgroupInclusiveAdd(uint value, out uint total) {
    uint inclusive = subgroupInclusiveAdd(value);
    if (gl_SubgroupInvocationID == subgroupMax(gl_SubgroupInvocationID)) {
        s_subgroup_sums[gl_SubgroupID] = inclusive;
    }
    barrier();
    uint before = 0u;
    total = 0u;
    for (uint s = 0u; s < gl_NumSubgroups; ++s) {
        if (s == gl_SubgroupID) before = total;
        total += s_subgroup_sums[s];
    }
    return before + inclusive;
}

void main() {
    uint local = gl_LocalInvocationIndex;
    // This invocation's slot of the block, in the order the subgroup scans add (the lanes of
    // earlier subgroups first); gl_LocalInvocationIndex need not follow it.
    uint lanes = subgroupAdd(1u);
    if (subgroupElect()) s_subgroup_lanes[gl_SubgroupID] = lanes;
    if (local == 0u) s_block = atomicAdd(status[kEmitChainedTicketWord], 1u);
    barrier();
    uint slot = subgroupExclusiveAdd(1u);
    for (uint sg = 0u; sg < gl_SubgroupID; ++sg) slot += s_subgroup_lanes[sg];
    uint block = s_block;
    ClearTileRanges(block);
    ZeroSmallSortRows(block);
    uint num_slots = max(view.num_splats, 1u);
    uint num_blocks = (num_slots + kEmitWorkgroupSize - 1u) / kEmitWorkgroupSize;
    if (block >= num_blocks) return;  // uniform: a spare workgroup, its ranges cleared
    uint k = block * kEmitWorkgroupSize + slot;
    for (uint p = 0u; p < kRadixSortMaxPasses; ++p) s_digit_counts[p * kRadixSortBins + local] = 0u;
    s_low_diff[local] = 0u;
    if (local == 0u) {
        s_low_diff[kRadixSortBins] = 0u;
        s_low_cycles = 0u;
    }
    uint count = ListSlotTileCount(k);

    // The block's scan in slot order. <= 256 counts of at most the tiles of an image each:
    // no wrap.
    uint block_sum = 0u;
    uint inclusive = WorkgroupInclusiveAdd(count, block_sum);
    if (gl_SubgroupID == 0u) {
        uint own = min(block_sum, kRadixSweepValueMask);
        uint prefix = LookBack(block, own);
        if (gl_SubgroupInvocationID == 0u) {
            s_block_total = own;
            s_prefix = prefix;
        }
    }
    barrier();
    uint local_begin = inclusive - count;
    uint begin = min(s_prefix + local_begin, kRadixSweepValueMask);
    uint end = min(begin + count, kRadixSweepValueMask);
    uint capacity = view.entry_capacity;
    if (count != 0u && begin <= capacity && end > capacity) {
        WriteEntryCount(begin, kErrorEntriesDropped);  // the first splat that does not fit
    }
    if (block == num_blocks - 1u && local == 0u) {
        uint total = min(s_prefix + s_block_total, kRadixSweepValueMask);
        counters.requested_entries = total;
        if (total <= capacity) {
            WriteEntryCount(total, 0u);
        } else if (capacity < view.max_tile_entries_total) {
            // The allocation, not RenderConfig::max_tile_entries_total, was the binding limit.
            atomicOr(counters.error_flags, kErrorCountsClamped);
        }
    }
    if (count != 0u && end <= capacity) {
        EmitEntries(ListValueSplat(splat_indices[k], view.num_splats), begin, end, false);
    }
    // The tile sort's first pass reads status table 0 (the depth sort used the same words).
    ZeroLargeSortRows(min(s_prefix, capacity), min(s_prefix + s_block_total, capacity));
    barrier();
    // The first pass's counts: the difference array's inclusive prefix sums in bin order,
    // bin = slot (the words wrap modulo 2^32 but every sum is a count), and the whole cycles.
    uint unused_total;
    uint low = WorkgroupInclusiveAdd(s_low_diff[slot], unused_total);
    if (slot < (1u << RadixSortDigitBits(0u, view.tile_bits))) s_digit_counts[slot] += low + s_low_cycles;
    uint passes = TileSortPasses();
    for (uint p = 0u; p < passes; ++p) {
        uint c = s_digit_counts[p * kRadixSortBins + slot];
        if (c != 0u) atomicAdd(tile_sort_state.histogram[p * kRadixSortBins + slot], c);
    }
}
