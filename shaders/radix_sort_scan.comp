#version 460
// Pass 2 of a digit: one workgroup per digit turns its row of block counts into exclusive
// offsets (in block order, which keeps the sort stable) and stores the digit's total.
#extension GL_GOOGLE_include_directive : require
#include "radix_sort_common.glsl"

layout(local_size_x = kRadixSortWorkgroupSize) in;

layout(std430, set = 0, binding = kRadixSortParamsBinding) readonly buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortHistogramBinding) buffer HistogramBlock {
    uint histogram[];
};

void main() {
    InitScanSlot();
    uint digit = gl_WorkGroupID.x;
    uint num_blocks = params.num_blocks;
    uint row = kRadixSortBins + digit * num_blocks;
    uint running = 0u;
    // num_blocks is uniform, so every invocation takes the barriers inside the scan.
    for (uint begin = 0u; begin < num_blocks; begin += kRadixSortWorkgroupSize) {
        uint block = begin + g_slot;
        uint value = block < num_blocks ? histogram[row + block] : 0u;
        uint total;
        uint prefix = WorkgroupExclusiveAdd(value, total);
        if (block < num_blocks) histogram[row + block] = running + prefix;
        running += total;
    }
    if (g_slot == 0u) histogram[digit] = running;
}
