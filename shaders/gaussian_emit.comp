#version 460
// Stage A, tile entries: one invocation per visible splat in depth order writes
// (tile index, splat index) for every tile of its rectangle at its scanned offset. A
// splat whose entries would pass the capacity writes none (the dispatch-args pass has
// flagged it). Entries leave here in depth order; a stable sort by tile keeps that order.
#extension GL_GOOGLE_include_directive : require
#include "GaussianSplatContract.h"

layout(local_size_x = kEmitWorkgroupSize) in;

layout(std430, set = 0, binding = kStageAViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(std430, set = 0, binding = kStageAProjectedBinding) readonly buffer ProjectedBlock {
    GaussianProjectedSplat projected[];
};
layout(std430, set = 0, binding = kStageACountersBinding) readonly buffer CountersBlock {
    GaussianStageACounters counters;
};
layout(std430, set = 0, binding = kStageASplatIndexBinding) readonly buffer SplatIndexBlock {
    uint splat_indices[];
};
layout(std430, set = 0, binding = kStageAScanBinding) readonly buffer ScanBlock {
    uint scan[];
};
layout(std430, set = 0, binding = kStageAEntryKeysBinding) writeonly buffer EntryKeysBlock {
    uint entry_keys[];
};
layout(std430, set = 0, binding = kStageAEntryValuesBinding) writeonly buffer EntryValuesBlock {
    uint entry_values[];
};

void main() {
    uint k = gl_GlobalInvocationID.x;
    uint visible = counters.visible_count;
    if (k >= visible) return;
    uint begin = scan[k];
    uint end = k + 1u < visible ? scan[k + 1u] : counters.requested_entries;
    if (end > view.limits.x || end == begin) return;
    uint splat = splat_indices[k];
    uvec4 tiles = projected[splat].tiles;
    uint min_x = tiles.x & 0xFFFFu, min_y = tiles.x >> 16u;
    uint max_x = tiles.y & 0xFFFFu, max_y = tiles.y >> 16u;
    uint tiles_x = view.image.z;
    uint out_index = begin;
    for (uint ty = min_y; ty < max_y; ++ty) {
        for (uint tx = min_x; tx < max_x; ++tx) {
            entry_keys[out_index] = ty * tiles_x + tx;
            entry_values[out_index] = splat;
            ++out_index;
        }
    }
}
