#version 460
// After an odd number of passes the sorted pairs sit in the scratch buffers: copy the
// first `count` of them back so the result always ends in the caller's buffers (a one-sweep
// sort: the kept pairs, the total of its digit histogram).
#extension GL_GOOGLE_include_directive : require
#include "radix_sort_common.glsl"

layout(local_size_x = kRadixSortWorkgroupSize) in;

layout(std430, set = 0, binding = kRadixSortParamsBinding) readonly buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortKeysInBinding) readonly buffer KeysInBlock {
    uint keys_in[];
};
layout(std430, set = 0, binding = kRadixSortValuesInBinding) readonly buffer ValuesInBlock {
    uint values_in[];
};
layout(std430, set = 0, binding = kRadixSortKeysOutBinding) writeonly buffer KeysOutBlock {
    uint keys_out[];
};
layout(std430, set = 0, binding = kRadixSortValuesOutBinding) writeonly buffer ValuesOutBlock {
    uint values_out[];
};
// Read by a one-sweep sort's copy only (the multi-pass sort binds a placeholder).
layout(std430, set = 0, binding = kRadixSortSweepStateBinding) readonly buffer SweepStateBlock {
    RadixSweepState state;
};

void main() {
    uint count = params.count;
    if (pc.sweep != 0u) {
        InitScanSlot();
        WorkgroupExclusiveAdd(state.histogram[g_slot], count);
    }
    uint block_size = params.block_size;
    uint block_begin = FlatWorkGroupIndex() * block_size;  // spare workgroups: past count
    for (uint i = gl_LocalInvocationIndex; i < block_size; i += kRadixSortWorkgroupSize) {
        uint index = block_begin + i;
        if (index < count) {
            if (pc.values_only == 0u) keys_out[index] = keys_in[index];
            values_out[index] = values_in[index];
        }
    }
}
