#version 460
// The offscreen hand-over on the GPU: the premultiplied splat colour (the composite's RGBA16F
// output, a = 1 - T) over Filament's RGBA8 mesh colour, rounded to 8 bits the way the host
// blend of the host-copy path does (FilamentRenderer's BlendOver):
//   out = round(255 * clamp(s + (1 - s_a) * m / 255, 0, 1)) per channel, alpha included.
// Written as one packed RGBA8 word per pixel, top row first, for an 8-bit readback.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "GaussianSplatCompositeContract.h"

layout(local_size_x = kBlendOverWorkgroupSize, local_size_y = kBlendOverWorkgroupSize) in;

layout(push_constant, std430) uniform PushConstantsBlock {
    GaussianBlendOverPushConstants pc;
};

layout(set = 0, binding = kBlendOverSplatColorBinding, rgba16f) readonly uniform image2D
    splat_color;
layout(set = 0, binding = kBlendOverMeshColorBinding) uniform texture2D mesh_color;
layout(set = 0, binding = kBlendOverOutputBinding, std430) writeonly buffer OutputBlock {
    uint out_rgba8[];
};

// round() of GLSL may round halves either way; the host's lround rounds them up (the values
// are never negative here).
uint RoundToByte(float v) {
    float x = clamp(v, 0.0, 1.0) * 255.0;
    float whole = floor(x);
    return uint(whole) + (x - whole >= 0.5 ? 1u : 0u);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    vec4 s = imageLoad(splat_color, pixel);
    int y = pc.mesh_flip_y != 0u ? int(pc.height) - 1 - pixel.y : pixel.y;
    // The 8-bit value exactly, then divided as the host divides (m / 255).
    uvec4 m8 = uvec4(round(texelFetch(mesh_color, ivec2(pixel.x, y), 0) * 255.0));
    vec4 m = vec4(m8) / 255.0;
    float transmit = 1.0 - s.a;
    uint packed = 0u;
    for (int c = 0; c < 4; ++c) packed |= RoundToByte(s[c] + transmit * m[c]) << (8 * c);
    out_rgba8[pixel.y * int(pc.width) + pixel.x] = packed;
}
