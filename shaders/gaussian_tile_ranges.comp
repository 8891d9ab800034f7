#version 460
// Stage B, before the composite: each tile's range [begin, end) of the tile-sorted entries.
// An entry that starts (ends) a run of equal tile keys writes its tile's begin (end); the
// recorder zeroed the ranges, so tiles without entries keep the empty range [0, 0). This
// replaces a binary search per tile in the composite, whose ~20 dependent loads were paid
// again by every tile a workgroup took. A grid-stride loop: the grid is sized from the
// capacity, the count is only known on the GPU.
#extension GL_GOOGLE_include_directive : require
#include "GaussianSplatContract.h"

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

void main() {
    uint count = min(counts[pc.entries.x], pc.entries.y);
    uint num_tiles = pc.image.z * pc.image.w;
    uint stride = gl_NumWorkGroups.x * kCompositeWorkgroupSize;
    for (uint i = gl_GlobalInvocationID.x; i < count; i += stride) {
        uint tile = entry_keys[i];
        if (tile >= num_tiles) continue;  // no such tile: never composited
        if (i == 0u || entry_keys[i - 1u] != tile) tile_ranges[tile].x = i;
        if (i + 1u == count || entry_keys[i + 1u] != tile) tile_ranges[tile].y = i + 1u;
    }
}
