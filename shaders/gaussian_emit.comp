#version 460
// Stage A, tile entries: one invocation per visible splat in list order writes
// (key, splat index) for every tile of its rectangle that TileRowSpan keeps, at its scanned
// offset; splats with kEmitSubgroupEntries or more are written by the whole subgroup. A
// splat whose entries would pass the capacity writes none (the dispatch-args pass has
// flagged it).
// Exact order (kEmitTileKeys): the list is in depth order and the key is the tile index;
// a stable sort by tile keeps that order. Packed option (kEmitPackedKeys): the list is in
// the projection's append order and the key is the seed's packed (tile, truncated depth)
// key, sorted on all 32 bits; kEmitUnpackKeys then turns the sorted keys back into tile
// indices, so later stages read the same layout in both modes.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#include "GaussianSplatContract.h"

layout(local_size_x = kEmitWorkgroupSize) in;

layout(constant_id = kSpecEmitMode) const uint kEmitMode = kEmitTileKeys;

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
layout(std430, set = 0, binding = kStageAEntryKeysBinding) buffer EntryKeysBlock {
    uint entry_keys[];
};
layout(std430, set = 0, binding = kStageAEntryValuesBinding) writeonly buffer EntryValuesBlock {
    uint entry_values[];
};

// Sorted packed keys -> tile indices. Dispatched with the emit pass's indirect size (one
// invocation per visible splat, rounded up), so it strides over the entries.
void UnpackKeys() {
    uint depth_bits = kSortKeyBits - view.limits.w;
    uint count = counters.entry_count;
    uint stride = gl_NumWorkGroups.x * kEmitWorkgroupSize;
    for (uint i = gl_GlobalInvocationID.x; i < count; i += stride) {
        entry_keys[i] = entry_keys[i] >> depth_bits;
    }
}

// Writes splat's entries [begin, end) in row order: this lane takes tiles lane, lane +
// stride, ... of every row (one lane alone: lane 0, stride 1; a whole subgroup: its lanes).
// The order of one splat's entries does not matter: they are in different tiles, and the
// tile sort is stable, so each tile still lists splats in the scanned (depth) order.
void EmitSplat(uint splat, uint begin, uint end, uint lane, uint stride) {
    uvec4 tiles = projected[splat].tiles;
    uint min_x = tiles.x & 0xFFFFu, min_y = tiles.x >> 16u;
    uint max_x = tiles.y & 0xFFFFu, max_y = tiles.y >> 16u;
    uint tiles_x = view.image.z;
    vec4 cdo = projected[splat].center_depth_opacity;
    vec4 conic = projected[splat].conic;
    float det_q = projected[splat].color.w;
    // The same float32 view depth the exact order sorts by (the projection's output).
    float norm_depth =
        kEmitMode == kEmitPackedKeys ? PackedSortKeyDepth(cdo.z, view.clip.z, view.clip.w) : 0.0;
    uint tile_bits = view.limits.w;
    uint row_begin = begin;
    for (uint ty = min_y; ty < max_y && row_begin < end; ++ty) {
        uint span = TileRowSpan(cdo.x, cdo.y, conic.x, conic.y, conic.z, det_q, conic.w, ty,
                                min_x, max_x);
        uint first = span & 0xFFFFu;
        uint n = min(TileSpanCount(span), end - row_begin);
        for (uint i = lane; i < n; i += stride) {
            uint tile = ty * tiles_x + first + i;
            entry_keys[row_begin + i] =
                kEmitMode == kEmitPackedKeys ? PackedSortKey(tile, norm_depth, tile_bits) : tile;
            entry_values[row_begin + i] = splat;
        }
        row_begin += n;
    }
    // The projection counted these spans from the same stored values with the same
    // `precise` code, so this never runs; should a driver still round differently, the
    // slots get a key past every tile (tile bits cover tiles_x * tiles_y + 1 values), which
    // sorts last and is never composited, instead of leaving stale entries.
    for (uint i = row_begin + lane; i < end; i += stride) {
        entry_keys[i] = 0xFFFFFFFFu;
        entry_values[i] = splat;
    }
}

void main() {
    if (kEmitMode == kEmitUnpackKeys) {
        UnpackKeys();
        return;
    }
    // Every lane stays to the end: the subgroup shares large splats below.
    uint k = gl_GlobalInvocationID.x;
    uint visible = counters.visible_count;
    bool emits = false;
    uint begin = 0u, end = 0u, splat = 0u;
    if (k < visible) {
        begin = scan[k];
        end = k + 1u < visible ? scan[k + 1u] : counters.requested_entries;
        emits = end <= view.limits.x && end > begin;
        splat = splat_indices[k];
    }
    bool shared_work = emits && end - begin >= kEmitSubgroupEntries;
    if (emits && !shared_work) EmitSplat(splat, begin, end, 0u, 1u);
    // A splat with many entries is emitted by the whole subgroup, one after another, so
    // that one invocation's thousands of stores do not hold up the dispatch.
    uvec4 queue = subgroupBallot(shared_work);
    while (subgroupBallotBitCount(queue) > 0u) {  // uniform over the subgroup
        uint owner = subgroupBallotFindLSB(queue);
        EmitSplat(subgroupShuffle(splat, owner), subgroupShuffle(begin, owner),
                  subgroupShuffle(end, owner), gl_SubgroupInvocationID, gl_SubgroupSize);
        queue[owner >> 5u] &= ~(1u << (owner & 31u));
    }
}
