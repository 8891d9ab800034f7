#version 460
// Reads the element count written on the GPU by the producer, clamps it to max_count and
// writes the indirect dispatch size of the per-block passes (no CPU readback).
#extension GL_GOOGLE_include_directive : require
#include "radix_sort_common.glsl"

layout(local_size_x = 1) in;

layout(std430, set = 0, binding = kRadixSortParamsBinding) writeonly buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortCountBinding) readonly buffer CountBlock {
    uint counts[];
};

void main() {
    uint count = counts[pc.count_index];
    uint flags = 0u;
    if (count > pc.max_count) {
        count = pc.max_count;
        flags = kErrorCountsClamped;
    }
    // No overflow: count <= max_count, which the host keeps far below 2^32 - block size.
    uint num_blocks = (count + kRadixSortBlockSize - 1u) / kRadixSortBlockSize;
    params.dispatch_x = num_blocks;
    params.dispatch_y = 1u;
    params.dispatch_z = 1u;
    params.count = count;
    params.num_blocks = num_blocks;
    params.flags = flags;
    params.reserved0 = 0u;
    params.reserved1 = 0u;
}
