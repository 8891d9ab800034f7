#version 460
// Composite stage, before the composite: each tile's range [begin, end) of the tile-sorted entries.
// An entry that starts (ends) a run of equal tile keys writes its tile's begin (end); the
// recorder zeroed the ranges, so tiles without entries keep the empty range [0, 0). This
// replaces a binary search per tile in the composite, whose ~20 dependent loads were paid
// again by every tile a workgroup took. A grid-stride loop: the grid is sized from the
// capacity, the count is only known on the GPU.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "GaussianSplatCompositeContract.h"

layout(local_size_x = kCompositeWorkgroupSize) in;

layout(push_constant, std430) uniform PushConstantsBlock {
    GaussianCompositePushConstants pc;
};

layout(std430, set = 0, binding = kCompositeEntryKeysBinding) readonly buffer KeysBlock {
    uint entry_keys[];  // tile index, ascending
};
layout(std430, set = 0, binding = kCompositeCountBinding) readonly buffer CountBlock {
    uint counts[];
};
layout(std430, set = 0, binding = kCompositeStateBinding) writeonly buffer StateBlock {
    GaussianCompositeState state;
    uvec2 tile_ranges[];
};

// Entries each invocation examines per step of the grid-stride loop, loaded together: one
// entry per step makes a chain of dependent loads per invocation (docs/perf/h200.md).
const uint kRangeItems = 4u;

void main() {
    uint count = min(counts[pc.count_index], pc.entry_capacity);
    uint num_tiles = pc.tiles_x * pc.tiles_y;
    uint stride = gl_NumWorkGroups.x * kCompositeWorkgroupSize;
    for (uint first = gl_GlobalInvocationID.x; first < count; first += kRangeItems * stride) {
        uint keys[kRangeItems];
        uint before[kRangeItems];
        uint after[kRangeItems];
        [[unroll]] for (uint k = 0u; k < kRangeItems; ++k) {
            uint i = first + k * stride;
            keys[k] = i < count ? entry_keys[i] : 0xFFFFFFFFu;
            before[k] = i > 0u && i < count ? entry_keys[i - 1u] : 0xFFFFFFFFu;
            after[k] = i + 1u < count ? entry_keys[i + 1u] : 0xFFFFFFFFu;
        }
        [[unroll]] for (uint k = 0u; k < kRangeItems; ++k) {
            uint i = first + k * stride;
            uint tile = keys[k];
            if (i >= count || tile >= num_tiles) continue;  // no such tile: never composited
            if (i == 0u || before[k] != tile) tile_ranges[tile].x = i;
            if (i + 1u == count || after[k] != tile) tile_ranges[tile].y = i + 1u;
        }
    }
}
