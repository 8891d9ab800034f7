#version 460
// Reads the element count written on the GPU by the producer, clamps it to max_count,
// chooses the block size and writes the indirect dispatch size of the per-block passes (no
// CPU readback). RadixSort::GetStorageRequirements bounds the block count the same way.
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
    uint wave = kRadixSortWorkgroupSize * clamp(pc.target_blocks, 1u, kRadixSortTargetBlocks);
    uint chunks = clamp((count + wave - 1u) / wave, 1u, kRadixSortItemsPerInvocation);
    uint block_size = kRadixSortWorkgroupSize * chunks;
    uint num_blocks = (count + block_size - 1u) / block_size;
    params.dispatch_x = num_blocks;
    params.dispatch_y = 1u;
    params.dispatch_z = 1u;
    params.count = count;
    params.num_blocks = num_blocks;
    params.flags = flags;
    params.block_size = block_size;
    params.reserved1 = 0u;
}
