#version 460
// Geometry stage indirect sizes from GPU-side counts (no CPU readback between passes).
// After the projection (packed key only; the exact order's sizes depend on N alone and the
// host writes them): the scan levels and the emit pass, from the visible count. After the
// scan: how many entries fit, and the tile sort's parameters (RadixSortParamsFor, what the
// sort's setup dispatch would write). Splats emit whole or not at all, front to back, so
// the emitting splats are a prefix of the depth order: the first splat whose inclusive
// offset passes the capacity is found by binary search and everything from it is dropped.
#extension GL_GOOGLE_include_directive : require
#include "GaussianSplatTileListContract.h"

layout(local_size_x = 1) in;

layout(push_constant, std430) uniform PushConstantsBlock {
    GaussianDispatchArgsPushConstants pc;
};

layout(std430, set = 0, binding = kGeometryStageViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(std430, set = 0, binding = kGeometryStageCountersBinding) buffer CountersBlock {
    GaussianGeometryStageCounters counters;
};
layout(std430, set = 0, binding = kGeometryStageScanBinding) readonly buffer ScanBlock {
    uint scan[];
};
#include "gaussian_scan_offset.glsl"
layout(std430, set = 0, binding = kGeometryStageSortParamsBinding) writeonly buffer SortParamsBlock {
    RadixSortParams sort_params;
};

uint DivCeil(uint a, uint b) {
    return a / b + (a % b == 0u ? 0u : 1u);
}

void SizeScanAndEmit() {
    uint visible = counters.visible_count;
    uvec4 emit = DispatchGridFor(DivCeil(visible, kEmitWorkgroupSize), pc.max_groups_x);
    counters.emit_dispatch_x = emit.x;
    counters.emit_dispatch_y = emit.y;
    counters.emit_dispatch_z = 1u;
    for (uint level = 0u; level < kScanMaxLevels; ++level) {
        counters.scan_levels[level] = ScanLevelFor(visible, level, pc.num_levels, pc.max_groups_x);
    }
}

// Inclusive offset of sorted visible splat k: the next exclusive offset, or the total.
uint InclusiveOffset(uint k, uint visible, uint total) {
    return k + 1u < visible ? ScanOffset(k + 1u) : total;
}

void CountFittingEntries() {
    uint visible = counters.visible_count;
    uint total = counters.requested_entries;
    uint capacity = view.entry_capacity;
    // Smallest k whose inclusive offset exceeds the capacity (visible when none does). When
    // everything fits, none does: the search (a chain of 23 dependent loads for the grid's
    // 5.1M splats, one invocation) is skipped.
    uint lo = total <= capacity ? visible : 0u;
    uint hi = visible;
    while (lo < hi) {
        uint mid = lo + (hi - lo) / 2u;
        if (InclusiveOffset(mid, visible, total) > capacity) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    uint entries = lo < visible ? ScanOffset(lo) : total;
    counters.entry_count = entries;
    uint flags = 0u;
    if (entries < total) flags |= kErrorEntriesDropped;
    // The allocation, not RenderConfig::max_tile_entries_total, was the binding limit.
    if (total > capacity && capacity < view.max_tile_entries_total) flags |= kErrorCountsClamped;
    if (flags != 0u) atomicOr(counters.error_flags, flags);
    sort_params =
        RadixSortParamsFor(entries, pc.sort_max_count, pc.sort_target_blocks, pc.max_groups_x);
}

void main() {
    if (pc.mode == kDispatchArgsAfterProject) {
        SizeScanAndEmit();
    } else {
        CountFittingEntries();
    }
}
