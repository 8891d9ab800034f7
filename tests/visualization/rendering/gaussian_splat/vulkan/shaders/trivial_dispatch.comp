#version 460
// out[i] = 3 i + 1 for i < n; out[n] = the subgroup size the shader ran with.
#extension GL_KHR_shader_subgroup_basic : require

layout(local_size_x = 64) in;

layout(push_constant, std430) uniform PushConstantsBlock {
    uint n;
};
layout(std430, set = 0, binding = 0) writeonly buffer Out {
    uint values[];
};

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < n) values[i] = 3u * i + 1u;
    if (i == 0u) values[n] = gl_SubgroupSize;
}
