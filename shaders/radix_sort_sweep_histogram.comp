#version 460
// The one-sweep sort's first dispatch (RadixSort::Algorithm::kOneSweep): the digit counts of
// every pass at once, over the kept keys (a first pass with drop_max_keys leaves out
// kRadixSortDroppedKey), added to RadixSweepState::histogram with one atomic per non-zero
// bin and workgroup. An LSD pass moves pairs but never changes the set of keys, so the
// counts of every later digit are known before the first pass. Also zeroes the first pass's
// look-back status rows (the scatter of pass p zeroes pass p + 1's).
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
// Look-back status words: [2][max_blocks][kRadixSortBins], table 0 for the first pass.
layout(std430, set = 0, binding = kRadixSortHistogramBinding) writeonly buffer StatusBlock {
    uint status[];
};
layout(std430, set = 0, binding = kRadixSortSweepStateBinding) buffer SweepStateBlock {
    RadixSweepState state;
};

shared uint s_counts[kRadixSortMaxPasses * kRadixSortBins];

void main() {
    uint local = gl_LocalInvocationIndex;
    uint group = FlatWorkGroupIndex();
    uint groups = params.sweep_histogram_grid.w;
    if (group >= groups) return;  // a spare workgroup of the grid's last row
    [[unroll]] for (uint p = 0u; p < kRadixSortMaxPasses; ++p) {
        s_counts[p * kRadixSortBins + local] = 0u;
    }
    barrier();
    uint count = params.count;
    uint block_size = params.block_size;
    uint num_blocks = params.num_blocks;
    uint passes = pc.num_passes;
    uint chunks = block_size / kRadixSortWorkgroupSize;  // uniform, 1..8
    for (uint block = group; block < num_blocks; block += groups) {
        uint block_begin = block * block_size;
        // All loads first, so that they are in flight together.
        uint keys[kRadixSortItemsPerInvocation];
        [[unroll]] for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
            uint index = block_begin + local + k * kRadixSortWorkgroupSize;
            keys[k] = k < chunks && index < count ? keys_in[index] : kRadixSortDroppedKey;
        }
        [[unroll]] for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
            uint index = block_begin + local + k * kRadixSortWorkgroupSize;
            if (k < chunks && index < count && IsKept(keys[k])) {
                for (uint p = 0u; p < passes; ++p) {
                    uint digit = RadixSortDigit(keys[k], p, pc.num_bits);
                    atomicAdd(s_counts[p * kRadixSortBins + digit], 1u);
                }
            }
        }
        // The first pass's status row of this block starts "not published".
        status[block * kRadixSortBins + local] = 0u;
    }
    barrier();
    for (uint p = 0u; p < passes; ++p) {
        uint c = s_counts[p * kRadixSortBins + local];
        if (c != 0u) atomicAdd(state.histogram[p * kRadixSortBins + local], c);
    }
}
