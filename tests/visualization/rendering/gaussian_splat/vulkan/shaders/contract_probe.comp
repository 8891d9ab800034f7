#version 460
// Writes every member of the contract's structs by name, with the value the C++ test
// expects at that member's C++ offset: a layout mismatch between std430 and the
// static_asserted C++ structs shows up as a wrong value.
#extension GL_GOOGLE_include_directive : require
#include "GaussianSplatContract.h"

layout(local_size_x = 1) in;

layout(push_constant, std430) uniform PushConstantsBlock {
    RadixSortPushConstants pc;
};
layout(std430, set = 0, binding = 0) writeonly buffer ParamsOut {
    RadixSortParams params_out;
};
layout(std430, set = 0, binding = 1) writeonly buffer PushOut {
    RadixSortPushConstants push_out;
};

void main() {
    params_out.dispatch_x = 101u;
    params_out.dispatch_y = 102u;
    params_out.dispatch_z = 103u;
    params_out.count = 104u;
    params_out.num_blocks = 105u;
    params_out.flags = 106u;
    params_out.block_size = 107u;
    params_out.reserved1 = 108u;
    // Push constants read by member name, written back member by member.
    push_out.shift = pc.shift;
    push_out.digit_bits = pc.digit_bits;
    push_out.count_index = pc.count_index;
    push_out.max_count = pc.max_count;
    push_out.target_blocks = pc.target_blocks;
}
