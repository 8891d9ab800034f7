#version 460
// Reads the element count written on the GPU by the producer, clamps it to max_count,
// chooses the block size and writes the indirect dispatch size of the per-block passes (no
// CPU readback): RadixSortParamsFor in the contract header. RadixSort::GetStorageRequirements
// bounds the block count the same way.
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
    params = RadixSortParamsFor(counts[pc.count_index], pc.max_count, pc.target_blocks);
}
