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
    params_out.key_base = 108u;
    params_out.key_min = 114u;
    params_out.key_max = 115u;
    params_out.range_passes = 109u;
    for (uint pass = 0u; pass < kRadixSortMaxPasses; ++pass) {
        params_out.pass_blocks[pass] = uvec4(110u, 111u, 112u, 113u) + 10u * pass;
        params_out.pass_rows[pass] = uvec4(150u, 151u, 152u, 153u) + 10u * pass;
    }
    params_out.copy_blocks = uvec4(190u, 191u, 192u, 193u);
    // Push constants read by member name, written back member by member.
    push_out.shift = pc.shift;
    push_out.digit_bits = pc.digit_bits;
    push_out.count_index = pc.count_index;
    push_out.max_count = pc.max_count;
    push_out.target_blocks = pc.target_blocks;
    push_out.drop_max_keys = pc.drop_max_keys;
    push_out.key_range = pc.key_range;
    push_out.num_passes = pc.num_passes;
    push_out.values_only = pc.values_only;
}
