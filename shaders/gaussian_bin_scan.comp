#version 460
// Per-tile bins, after the projection: one workgroup turns every tile's entry count into
// its begin (an exclusive prefix sum over the tiles in row-major order) and sets the tile's
// cursor to it, for the emit pass's atomics. Tiles whose entries would pass the capacity
// get begin = cursor = capacity: they receive nothing, the frame is flagged and the
// entries kept are the tiles before the first that does not fit. Sums saturate at
// kScanSaturation, as the splat scan's do (a, b <= S: min(a + b, S) never wraps).
#extension GL_GOOGLE_include_directive : require
#include "GaussianSplatTileListContract.h"

layout(local_size_x = kBinScanWorkgroupSize) in;

layout(std430, set = 0, binding = kGeometryStageViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(std430, set = 0, binding = kGeometryStageCountersBinding) buffer CountersBlock {
    GaussianGeometryStageCounters counters;
};
layout(std430, set = 0, binding = kGeometryStageTileRangesBinding) buffer TileRangesBlock {
    uint tile_bins[];
};

shared uint s_sums[kBinScanWorkgroupSize];
shared uint s_kept;

uint SaturatingAdd(uint a, uint b) { return min(a + b, kScanSaturation); }

uint CountAt(uint tile) {
    return min(tile_bins[kBinRangesWordOffset + 2u * tile + 1u], kScanSaturation);
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    uint tiles = view.tiles_x * view.tiles_y;
    // Each invocation owns a contiguous run of tiles: one workgroup scan in all.
    uint chunk = (tiles + kBinScanWorkgroupSize - 1u) / kBinScanWorkgroupSize;
    uint first = min(lid * chunk, tiles);
    uint last = min(first + chunk, tiles);
    uint sum = 0u;
    for (uint t = first; t < last; ++t) sum = SaturatingAdd(sum, CountAt(t));
    s_sums[lid] = sum;
    if (lid == 0u) s_kept = 0u;
    barrier();
    for (uint d = 1u; d < kBinScanWorkgroupSize; d <<= 1u) {
        uint before = lid >= d ? s_sums[lid - d] : 0u;
        barrier();
        s_sums[lid] = SaturatingAdd(s_sums[lid], before);
        barrier();
    }
    uint total = s_sums[kBinScanWorkgroupSize - 1u];
    uint begin = lid > 0u ? s_sums[lid - 1u] : 0u;
    uint capacity = view.entry_capacity;
    uint kept = begin <= capacity ? begin : 0u;
    for (uint t = first; t < last; ++t) {
        uint end = SaturatingAdd(begin, CountAt(t));
        uint start = end <= capacity ? begin : capacity;
        if (end <= capacity) kept = end;
        tile_bins[kBinRangesWordOffset + 2u * t] = start;
        tile_bins[kBinRangesWordOffset + 2u * t + 1u] = start;
        begin = end;
    }
    // Ends ascend with the tile index, so the largest end that fits closes the kept prefix.
    atomicMax(s_kept, kept);
    barrier();
    if (lid == 0u) {
        uint entries = s_kept;
        counters.entry_count = entries;
        counters.requested_entries = total;
        uint flags = 0u;
        if (entries < total) flags |= kErrorEntriesDropped;
        // The allocation, not RenderConfig::max_tile_entries_total, was the binding limit.
        if (total > capacity && capacity < view.max_tile_entries_total) {
            flags |= kErrorCountsClamped;
        }
        if (flags != 0u) atomicOr(counters.error_flags, flags);
    }
}
