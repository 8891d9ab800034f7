#version 460
// Geometry stage, tile entries: one invocation per visible splat in list order writes
// (key, splat index) for every tile of its rectangle that TileRowSpan keeps, at its scanned
// offset (one invocation per splat: sharing splats of 32+ entries across the subgroup
// measured slower, docs/perf/h100.md "Geometry stage"). A splat whose entries would pass
// the capacity writes none (the dispatch-args pass has flagged it).
// Exact order (kEmitTileKeys): the list is in depth order and the key is the tile index;
// a stable sort by tile keeps that order. Packed option (kEmitPackedKeys): the list is in
// the projection's append order and the key is the seed's packed (tile, truncated depth)
// key, sorted on all 32 bits; kEmitUnpackKeys then turns the sorted keys back into tile
// indices, so later stages read the same layout in both modes.
// Per-tile bins (kEmitBinned): one invocation per slot of the projection; a visible slot
// writes (depth key, slot) at an atomic cursor of each of its tiles (the bin scan set the
// cursors to the tiles' begins, or past the capacity for tiles that do not fit);
// gaussian_bin_sort then orders each tile.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "GaussianSplatTileListContract.h"
#include "gaussian_device_address.glsl"

layout(local_size_x = kEmitWorkgroupSize) in;

layout(constant_id = kSpecEmitMode) const uint kEmitMode = kEmitTileKeys;

layout(std430, set = 0, binding = kGeometryStageViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(push_constant, std430) uniform AddressesBlock {
    layout(offset = kGeometryAddressesPushOffset) GaussianGeometryAddresses addresses;
};
layout(std430, set = 0, binding = kGeometryStageCountersBinding) readonly buffer CountersBlock {
    GaussianGeometryStageCounters counters;
};
layout(std430, set = 0, binding = kGeometryStageSplatIndexBinding) readonly buffer SplatIndexBlock {
    uint splat_indices[];
};
layout(std430, set = 0, binding = kGeometryStageScanBinding) readonly buffer ScanBlock {
    uint scan[];
};
#include "gaussian_scan_offset.glsl"
layout(std430, set = 0, binding = kGeometryStageDepthKeysBinding) readonly buffer DepthKeysBlock {
    uint depth_keys[];
};
layout(std430, set = 0, binding = kGeometryStageTileCountsBinding) readonly buffer TileCountsBlock {
    uint tile_counts[];
};
layout(std430, set = 0, binding = kGeometryStageTileRangesBinding) buffer TileRangesBlock {
    uint tile_bins[];
};
layout(std430, set = 0, binding = kGeometryStageEntryKeysBinding) buffer EntryKeysBlock {
    uint entry_keys[];
};
layout(std430, set = 0, binding = kGeometryStageEntryValuesBinding) writeonly buffer EntryValuesBlock {
    uint entry_values[];
};

#include "gaussian_emit_entries.glsl"

// Sorted packed keys -> tile indices. Dispatched with the emit pass's indirect size (one
// invocation per visible splat, rounded up), so it strides over the entries.
void UnpackKeys() {
    uint depth_bits = kSortKeyBits - view.tile_bits;
    uint count = counters.entry_count;
    uint stride = FlatNumWorkGroups() * kEmitWorkgroupSize;
    uint first = FlatWorkGroupIndex() * kEmitWorkgroupSize + gl_LocalInvocationIndex;
    for (uint i = first; i < count; i += stride) {
        entry_keys[i] = entry_keys[i] >> depth_bits;
    }
}

// One slot of the projection into the bins of its tiles (the rows' spans as the
// projection counted them).
void EmitBinned(uint k) {
    if (k >= view.num_splats) return;
    uint key = depth_keys[k];
    if (key == 0xFFFFFFFFu) return;  // culled, hidden or an empty slot of a cut's list
    uint count = tile_counts[k];
    if (count == 0u || count > view.max_tiles_per_splat) return;
    uint64_t projected = DeviceAddress(addresses.projected_lo, addresses.projected_hi);
    GaussianProjectedSplat record = LoadProjected(projected, k);
    uint min_x = record.rect_min & 0xFFFFu, min_y = record.rect_min >> 16u;
    uint max_x = record.rect_max & 0xFFFFu, max_y = record.rect_max >> 16u;
    bool whole_rect = count == (max_x - min_x) * (max_y - min_y);
    uint capacity = view.entry_capacity;
    for (uint ty = min_y; ty < max_y; ++ty) {
        uint span = whole_rect ? min_x | (max_x << 16u)
                               : TileRowSpan(record.center_x, record.center_y, record.conic.x,
                                             record.conic.y, record.conic.z, record.det_q,
                                             record.cull_threshold, ty, min_x, max_x);
        for (uint tx = span & 0xFFFFu; tx < (span >> 16u); ++tx) {
            uint tile = ty * view.tiles_x + tx;
            uint at = atomicAdd(tile_bins[kBinRangesWordOffset + 2u * tile + 1u], 1u);
            if (at < capacity) {
                entry_keys[at] = key;
                entry_values[at] = k;
            }
        }
    }
}

void main() {
    if (kEmitMode == kEmitUnpackKeys) {
        UnpackKeys();
        return;
    }
    if (kEmitMode == kEmitBinned) {
        EmitBinned(FlatWorkGroupIndex() * kEmitWorkgroupSize + gl_LocalInvocationIndex);
        return;
    }
    uint k = FlatWorkGroupIndex() * kEmitWorkgroupSize + gl_LocalInvocationIndex;
    uint visible = counters.visible_count;
    if (k >= visible) return;
    uint begin = ScanOffset(k);
    uint end = k + 1u < visible ? ScanOffset(k + 1u) : counters.requested_entries;
    if (end > view.entry_capacity || end == begin) return;
    EmitEntries(ListValueSplat(splat_indices[k], view.num_splats), begin, end,
                kEmitMode == kEmitPackedKeys);
}
