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

// The tile sort's digit counts of this workgroup's entries, pass-major.
shared uint s_digit_counts[kRadixSortMaxPasses * kRadixSortBins];

// The tile sort's passes over view.tile_bits key bits (RadixSort::GetNumPasses).
uint TileSortPasses() {
    return (view.tile_bits + kRadixSortDigitBits - 1u) / kRadixSortDigitBits;
}

void CountTileKey(uint key) {
    uint passes = TileSortPasses();
    for (uint p = 0u; p < passes; ++p) {
        atomicAdd(s_digit_counts[p * kRadixSortBins + RadixSortDigit(key, p, view.tile_bits)], 1u);
    }
}
#define OPEN3D_EMIT_COUNT_KEY(key) CountTileKey(key)

#include "gaussian_emit_entries.glsl"

shared uint s_block;
shared uint s_prefix;  // entries of the blocks before this one
shared uint s_block_total;
shared uint s_sums[kEmitWorkgroupSize];

#include "gaussian_list_count.glsl"

// The frame's entry count, flags and the tile sort's parameters, from the one slot that
// decides them.
void WriteEntryCount(uint entries, uint flags) {
    counters.entry_count = entries;
    if (flags != 0u) atomicOr(counters.error_flags, flags);
    sort_params =
        RadixSortParamsFor(entries, pc.sort_max_count, pc.sort_target_blocks, pc.max_groups_x);
}

// Block `block`'s prefix: its own total published as an aggregate, then the earlier blocks'
// words added walking back until one holds an inclusive prefix (waiting while a word is
// still 0: its block has started, so it will publish), then its own inclusive prefix.
uint LookBack(uint block, uint own) {
    uint word = kEmitChainedStatusBase + block;
    if (block == 0u) {
        atomicExchange(status[word], kRadixSweepFlagInclusive | own);
        return 0u;
    }
    atomicExchange(status[word], kRadixSweepFlagAggregate | own);
    uint prefix = 0u;
    uint back = block - 1u;
    while (true) {
        uint s = atomicAdd(status[kEmitChainedStatusBase + back], 0u);
        if (s == 0u) continue;  // not published yet
        prefix = min(prefix + (s & kRadixSweepValueMask), kRadixSweepValueMask);
        if ((s & kRadixSweepFlagInclusive) != 0u) break;
        --back;  // block 0 always publishes an inclusive prefix, so this stops there
    }
    if (kOddBlocksAggregateOnly == 0u || (block & 1u) == 0u) {
        atomicExchange(status[word],
                       kRadixSweepFlagInclusive | min(prefix + own, kRadixSweepValueMask));
    }
    return prefix;
}

void main() {
    uint local = gl_LocalInvocationIndex;
    if (local == 0u) s_block = atomicAdd(status[kEmitChainedTicketWord], 1u);
    barrier();
    uint block = s_block;
    uint num_slots = max(view.num_splats, 1u);
    uint num_blocks = (num_slots + kEmitWorkgroupSize - 1u) / kEmitWorkgroupSize;
    if (block >= num_blocks) return;  // uniform: a spare workgroup of the grid's last row
    uint k = block * kEmitWorkgroupSize + local;
    for (uint p = 0u; p < kRadixSortMaxPasses; ++p) s_digit_counts[p * kRadixSortBins + local] = 0u;
    uint count = ListSlotTileCount(k);

    // Workgroup inclusive scan (Hillis-Steele) in shared memory by local index, so the
    // result does not depend on how invocations form subgroups. <= 256 counts of at most
    // the tiles of an image each: no wrap.
    s_sums[local] = count;
    barrier();
    for (uint offset = 1u; offset < kEmitWorkgroupSize; offset <<= 1u) {
        uint other = local >= offset ? s_sums[local - offset] : 0u;
        barrier();
        s_sums[local] += other;
        barrier();
    }
    if (local == 0u) {
        uint own = min(s_sums[kEmitWorkgroupSize - 1u], kRadixSweepValueMask);
        s_block_total = own;
        s_prefix = LookBack(block, own);
    }
    barrier();
    uint local_begin = s_sums[local] - count;
    uint begin = min(s_prefix + local_begin, kRadixSweepValueMask);
    uint end = min(begin + count, kRadixSweepValueMask);
    uint capacity = view.entry_capacity;
    if (count != 0u && begin <= capacity && end > capacity) {
        WriteEntryCount(begin, kErrorEntriesDropped);  // the first splat that does not fit
    }
    if (block == num_blocks - 1u && local == kEmitWorkgroupSize - 1u) {
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
    // The tile sort's first pass reads status table 0, rows [0, its blocks): zero every row
    // it can have, spread over the workgroups (the depth sort used the same words). And every
    // tile's range starts empty.
    uint status_words = RadixSortMaxBlocks(capacity, pc.sort_target_blocks) * kRadixSortBins;
    uint stride = num_blocks * kEmitWorkgroupSize;
    for (uint i = block * kEmitWorkgroupSize + local; i < status_words; i += stride) {
        sort_status[i] = 0u;
    }
    uint num_tiles = view.tiles_x * view.tiles_y;
    // The state's header (the composite's tile counter) starts at zero too
    // (CompositeStageInputs::state_zeroed).
    if (block == 0u && local < kBinRangesWordOffset) tile_ranges[local] = 0u;
    for (uint t = block * kEmitWorkgroupSize + local; t < num_tiles; t += stride) {
        tile_ranges[kBinRangesWordOffset + 2u * t] = 0xFFFFFFFFu;
        tile_ranges[kBinRangesWordOffset + 2u * t + 1u] = 0u;
    }
    barrier();
    uint passes = TileSortPasses();
    for (uint p = 0u; p < passes; ++p) {
        uint c = s_digit_counts[p * kRadixSortBins + local];
        if (c != 0u) atomicAdd(tile_sort_state.histogram[p * kRadixSortBins + local], c);
    }
}
