#version 460
// Pass 1 of a digit: per-block digit counts, stored digit-major so that one exclusive scan
// per digit row (radix_sort_scan.comp) gives every block its output offset within a digit.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "radix_sort_common.glsl"

layout(local_size_x = kRadixSortWorkgroupSize) in;

layout(std430, set = 0, binding = kRadixSortParamsBinding) readonly buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortKeysInBinding) readonly buffer KeysBlock {
    uint keys_in[];
};
// [kRadixSortBins] digit totals, then [kRadixSortBins][num_blocks] block counts.
layout(std430, set = 0, binding = kRadixSortHistogramBinding) writeonly buffer HistogramBlock {
    uint histogram[];
};

shared uint s_counts[kRadixSortBins];

void main() {
    uint local = gl_LocalInvocationIndex;
    s_counts[local] = 0u;
    barrier();
    uint count = params.count;
    uint block_size = params.block_size;
    uint block_begin = gl_WorkGroupID.x * block_size;
    uint chunks = block_size / kRadixSortWorkgroupSize;  // uniform, 1..8
    // All loads first, so that they are in flight together (one load, then its atomic, per
    // step took 20-37 us per pass of the grid's sorts on the H200).
    uint keys[kRadixSortItemsPerInvocation];
    [[unroll]] for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        uint index = block_begin + local + k * kRadixSortWorkgroupSize;
        keys[k] = k < chunks && index < count ? keys_in[index] : 0u;
    }
    [[unroll]] for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        uint index = block_begin + local + k * kRadixSortWorkgroupSize;
        if (k < chunks && index < count && IsKept(keys[k])) {
            atomicAdd(s_counts[DigitOf(keys[k])], 1u);
        }
    }
    barrier();
    histogram[kRadixSortBins + local * params.num_blocks + gl_WorkGroupID.x] = s_counts[local];
}
